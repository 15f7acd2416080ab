// The light tree's pdf is the probability with which it samples each light,
// it sums to 1, and it never misses a light with a non-zero term.
#include <catch2/catch.hpp>

#include <bit>

#include "accretion/lighting/light_tree.h"
#include "accretion/particles/particle_source.h"
#include "support/statistics.h"
#include "support/test_scenes.h"

using namespace accretion;

TEST_CASE("light tree pdf equals sampling frequency, sums to 1, covers every lit light", "[lighttree][statistical]") {
    const ShadingModel model = GENERATE(ShadingModel::lambert, ShadingModel::isotropic);
    INFO("model " << enumName(model));
    const accretion::test::DiskLights disk(model);
    const auto& [s, particles, tree] = disk;
    const auto N = static_cast<std::uint32_t>(particles.size());
    REQUIRE(tree.nodeCount() == 2 * std::size_t(N) - 1);

    // A receiver on particle 3, normal tilted so some lights are below the horizon.
    const ShadingPoint sp{particles.position[3], glm::normalize(Vec3(0.3f, 1.0f, 0.2f)), Vec3(0, 1, 0),
                          Vec3(0.8f), 3};
    const float dmin2 = 0.0f;
    double pdfSum = 0.0;
    std::vector<double> pdf(N);
    for (std::uint32_t i = 0; i < N; ++i) {
        pdf[i] = tree.pdf(sp, i);
        pdfSum += pdf[i];
        LightTerm t;
        const bool lit = i != sp.self && evalLight(model, sp, particles.position[i], particles.emission[i],
                                                   std::max(dmin2, particles.radius[i] * particles.radius[i]), t);
        INFO("light " << i);
        if (lit) CHECK(pdf[i] > 0.0);  // unbiased: every non-zero term can be drawn
        if (i == sp.self) CHECK(pdf[i] == 0.0);
    }
    // A traversal can end where both children bound to 0 (every light below
    // them is below the horizon or is the receiver): that outcome carries the
    // rest of the probability, and a zero term, so the estimator stays unbiased.
    REQUIRE(pdfSum <= 1.0 + 1e-4);
    if (model == ShadingModel::isotropic) CHECK(pdfSum == Approx(1.0).epsilon(1e-4));

    const int trials = 300'000;
    std::vector<double> observed(N + 1, 0.0), expected(N + 1);  // cell N: no light
    Rng rng(0, 0, RngPass::lightSampling, 5);
    double invPdfMean = 0.0;
    for (int t = 0; t < trials; ++t) {
        const LightSample x = tree.sample(sp, rng);
        if (x.i == kNoLightSample) {
            ++observed[N];
            continue;
        }
        REQUIRE(x.i < N);
        REQUIRE(x.pdf == tree.pdf(sp, x.i));  // the same arithmetic, bit for bit
        ++observed[x.i];
        invPdfMean += 1.0 / (double(x.pdf) * N);
    }
    invPdfMean /= trials;
    for (std::uint32_t i = 0; i < N; ++i) expected[i] = trials * pdf[i];
    expected[N] = trials * std::max(0.0, 1.0 - pdfSum);
    // Confidence 1e-4 (fixed seed).
    CHECK(accretion::test::chiSquarePValue(observed, expected) > 1e-4);
    // E[1 / (pdf N)] (0 for no light) = (lights with pdf > 0) / N: 1 when every light is reachable.
    std::size_t reachable = 0;
    for (double p : pdf) reachable += p > 0.0;
    CHECK(invPdfMean == Approx(double(reachable) / N).epsilon(0.05));
    if (model == ShadingModel::isotropic) CHECK(reachable == N - 1);
}

TEST_CASE("a receiver's memo of descent importances draws what the direct descent draws, bit for bit", "[lighttree]") {
    // LightTreeMemo keeps a shading point's node importances for all its
    // draws (restir's candidates). 64 draws per receiver over a tree of 1999
    // nodes, more than its 128 slots: neither a recalled value nor a slot
    // taken over by another node may change a draw or its pdf by a bit.
    const ShadingModel model = GENERATE(ShadingModel::lambert, ShadingModel::isotropic);
    INFO("model " << enumName(model));
    const accretion::test::DiskLights disk(model, 1000);
    const auto& [s, particles, tree] = disk;
    std::size_t draws = 0, lit = 0;
    for (std::uint32_t j = 0; j < particles.size(); j += 37) {
        const ShadingPoint sp{particles.position[j], glm::normalize(Vec3(0.2f * float(j % 7) - 0.6f, 1.0f, 0.1f)), Vec3(0, 1, 0),
                              Vec3(0.8f), j};
        LightTreeMemo memo;
        Rng direct(j, 0, RngPass::lightSampling, 9), recalled(j, 0, RngPass::lightSampling, 9);
        for (int k = 0; k < 64; ++k) {
            const LightSample a = tree.sample(sp, direct), b = tree.sample(sp, recalled, memo);
            REQUIRE(a.i == b.i);
            REQUIRE(std::bit_cast<std::uint32_t>(a.pdf) == std::bit_cast<std::uint32_t>(b.pdf));
            ++draws;
            lit += a.i != kNoLightSample;
        }
    }
    CHECK(draws == 28 * 64);
    CHECK(lit > draws / 2);
}
