#include <catch2/catch.hpp>

#include "accretion/core/rng.h"
#include "accretion/lighting/reservoir.h"
#include "support/statistics.h"

using namespace accretion;

namespace {

constexpr int kTrials = 400'000;

double sumOf(const std::vector<float>& w) {
    double total = 0.0;
    for (float x : w) total += x;
    return total;
}

/// The chi-square p-value of `observed` selections out of kTrials against
/// selection in proportion to w.
double proportionalPValue(const std::vector<double>& observed, const std::vector<float>& w) {
    std::vector<double> expected(w.size());
    for (std::size_t i = 0; i < w.size(); ++i) expected[i] = kTrials * w[i] / sumOf(w);
    return accretion::test::chiSquarePValue(observed, expected);
}

}  // namespace

TEST_CASE("streaming reservoir keeps candidate i with probability w_i / sum w (chi-square)", "[reservoir][statistical]") {
    const std::vector<float> w = {0.5f, 0.0f, 3.0f, 1.0f, 0.25f, 6.0f, 2.0f, 0.0f, 1.5f, 4.0f};
    const double total = sumOf(w);
    std::vector<double> observed(w.size(), 0.0);
    Rng rng(0, 0, RngPass::lightSampling, 77);
    for (int t = 0; t < kTrials; ++t) {
        Reservoir r;
        for (std::uint32_t i = 0; i < w.size(); ++i) r.update(i, w[i], 2.0f * w[i], rng.uniform());
        r.finalize();
        REQUIRE(r.M == w.size());
        REQUIRE(r.w_sum == Approx(total));
        REQUIRE(r.p_hat == 2.0f * w[r.y]);
        // W = w_sum / (M p_hat(y)): the seed's w_sum / M would not divide by p_hat.
        REQUIRE(r.W == Approx(total / (double(w.size()) * 2.0 * w[r.y])));
        ++observed[r.y];
    }
    REQUIRE(observed[1] == 0.0);
    REQUIRE(observed[7] == 0.0);
    // Confidence 1e-4 (fixed seed).
    CHECK(proportionalPValue(observed, w) > 1e-4);
}

TEST_CASE("an empty or all-zero reservoir has W = 0", "[reservoir]") {
    Reservoir r;
    r.finalize();
    REQUIRE(r.W == 0.0f);
    r.update(3, 0.0f, 0.0f, 0.5f);
    r.finalize();
    REQUIRE(r.y == kNoLight);
    REQUIRE(r.W == 0.0f);
    REQUIRE(r.M == 1);
}

TEST_CASE("merging reservoirs keeps candidate i with probability w_i / sum w (chi-square)", "[reservoir][statistical]") {
    // Two reservoirs stream disjoint halves; merging them with weight w_sum of
    // each (= p_hat W M for a shared target) must select from the union with
    // the same frequencies as one stream.
    const std::vector<float> w = {0.5f, 2.0f, 3.0f, 1.0f, 0.25f, 6.0f, 2.0f, 0.0f, 1.5f, 4.0f, 0.75f};
    const std::uint32_t split = 4;
    const double total = sumOf(w);
    std::vector<double> observed(w.size(), 0.0);
    Rng rng(1, 0, RngPass::lightSampling, 78);
    for (int t = 0; t < kTrials; ++t) {
        Reservoir a, b;
        for (std::uint32_t i = 0; i < split; ++i) a.update(i, w[i], w[i], rng.uniform());
        for (std::uint32_t i = split; i < w.size(); ++i) b.update(i, w[i], w[i], rng.uniform());
        a.finalize();
        b.finalize();
        Reservoir m;
        m.merge(a.y, a.p_hat * a.W * float(a.M), a.p_hat, a.M, rng.uniform());
        m.merge(b.y, b.p_hat * b.W * float(b.M), b.p_hat, b.M, rng.uniform());
        m.finalize();
        REQUIRE(m.M == w.size());
        REQUIRE(m.w_sum == Approx(total).epsilon(1e-5));
        ++observed[m.y];
    }
    REQUIRE(observed[7] == 0.0);
    CHECK(proportionalPValue(observed, w) > 1e-4);
}
