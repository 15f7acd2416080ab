// One chi-square harness over every light sampler: each draws lights with
// exactly the probabilities its pdf reports, the pdf sums to 1 (up to the
// mass of an empty draw), and a light with a non-zero term can be drawn.
#include <functional>

#include <catch2/catch.hpp>

#include "accretion/lighting/light_sampler.h"
#include "accretion/lighting/light_tiles.h"
#include "accretion/lighting/regir_grid.h"
#include "accretion/lighting/source_pmf.h"
#include "accretion/particles/particle_source.h"
#include "support/statistics.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

/// A sampler under test: draw (with its stream) and pdf, at one receiver.
struct SamplerUnderTest {
    const char* name;
    std::function<LightSample(Rng&)> sample;
    std::function<float(std::uint32_t)> pdf;
};

/// Draws N lights; the chi-square p-value of the counts against N pdf(i)
/// must exceed 1e-4 (a correct sampler fails one run in 10^4).
void checkSampler(const SamplerUnderTest& s, std::uint32_t lights, const std::vector<bool>& lit) {
    INFO("sampler " << s.name);
    const std::uint32_t N = 400000;
    std::vector<double> observed(lights + 1, 0.0), expected(lights + 1, 0.0);
    Rng rng(7, 0, RngPass::lightSampling, 11);
    std::uint32_t pdfMismatches = 0, outOfRange = 0;
    for (std::uint32_t n = 0; n < N; ++n) {
        const LightSample x = s.sample(rng);
        if (x.i == kNoLightSample) {
            observed[lights] += 1.0;
            continue;
        }
        if (x.i >= lights) {
            ++outOfRange;
            continue;
        }
        if (std::abs(x.pdf - s.pdf(x.i)) > 1e-6f * x.pdf) ++pdfMismatches;  // sample reports the pdf that pdf() gives
        observed[x.i] += 1.0;
    }
    CHECK(outOfRange == 0);
    CHECK(pdfMismatches == 0);
    double sum = 0.0;
    for (std::uint32_t i = 0; i < lights; ++i) {
        const double p = s.pdf(i);
        if (lit[i]) CHECK(p > 0.0);
        expected[i] = N * p;
        sum += p;
    }
    CHECK(sum <= 1.0 + 1e-5);
    expected[lights] = N * std::max(0.0, 1.0 - sum);  // an empty draw (tree: every light below the horizon)
    CHECK(accretion::test::chiSquarePValue(observed, expected) > 1e-4);
}

/// 300 particles of the small disk with their light arrays and power
/// table, and a receiver on particle 3 whose tilted normal leaves some
/// lights below its horizon.
struct SamplerScene {
    Settings s = [] {
        Settings d = accretion::test::smallDiskSettings();
        d.particles.count = 300;
        return d;
    }();
    Particles particles = ParticleSource(s).frame(0);
    std::uint32_t N = static_cast<std::uint32_t>(particles.size());
    LightArrays L{particles, s.shading};
    AliasTable power = buildPowerTable(particles);
    ShadingPoint sp{particles.position[3], glm::normalize(Vec3(0.3f, 1.0f, 0.2f)), Vec3(0, 1, 0), Vec3(0.8f), 3,
                    particles.position[3], Vec3(0.0f)};
};

}  // namespace

TEST_CASE("every light sampler draws in proportion to its pdf (one chi-square harness)", "[lighting][sampler][statistical]") {
    const SamplerScene scene;
    const auto& [s, particles, N, L, power, sp] = scene;
    const LightTree tree(particles, s.shading);
    std::vector<bool> lit(N), emits(N);
    for (std::uint32_t i = 0; i < N; ++i) {
        LightTerm t;
        lit[i] = L.term<ShadingModel::lambert>(sp, i, t);
        emits[i] = luminance(particles.emission[i]) > 0.0f;
    }
    // The source pdfs against their closed forms, computed here from the particles:
    // 1 / N, and luminance(I_i) / sum of luminance (the frequencies are then checked against these).
    double total = 0.0;
    for (const Vec3& I : particles.emission) total += 0.2126 * I.x + 0.7152 * I.y + 0.0722 * I.z;
    for (std::uint32_t i = 0; i < N; ++i) {
        const Vec3& I = particles.emission[i];
        CHECK(sourcePdf<false>(L, nullptr, i) == Approx(1.0 / N).epsilon(1e-6));
        CHECK(sourcePdf<true>(L, &power, i) ==
              Approx((0.2126 * I.x + 0.7152 * I.y + 0.0722 * I.z) / total).epsilon(1e-5).margin(1e-12));
    }
    checkSampler({"uniform", [&](Rng& rng) { return sampleSource<false>(L, nullptr, rng); },
                  [&](std::uint32_t i) { return sourcePdf<false>(L, nullptr, i); }},
                 N, emits);
    checkSampler({"power", [&](Rng& rng) { return sampleSource<true>(L, &power, rng); },
                  [&](std::uint32_t i) { return sourcePdf<true>(L, &power, i); }},
                 N, emits);
    checkSampler({"tree", [&](Rng& rng) { return tree.sample(sp, rng); }, [&](std::uint32_t i) { return tree.pdf(sp, i); }},
                 N, lit);
    // The candidate sources of ris / restir (render.source) through the same harness.
    const CandidateSampler<LightSource::power> powerCandidates{L, &power, &tree};
    checkSampler({"candidates: power", [&](Rng& rng) { return powerCandidates.sample(sp, rng); },
                  [&](std::uint32_t i) { return powerCandidates.pmf(sp, i); }},
                 N, emits);
    const CandidateSampler<LightSource::tree> treeCandidates{L, &power, &tree};
    checkSampler({"candidates: tree", [&](Rng& rng) { return treeCandidates.sample(sp, rng); },
                  [&](std::uint32_t i) { return treeCandidates.pmf(sp, i); }},
                 N, lit);
    // split: the far lights, drawn with the 20 nearest taken out of the tree
    // (a near light drawn would report a pdf that pdfFar gives as 0: a mismatch).
    NearField near;
    tree.nearest(sp, 20, near);
    REQUIRE(near.count == 21);  // and the receiver's own
    std::vector<bool> litFar = lit;
    for (std::uint32_t k = 0; k < near.count; ++k) litFar[near.light[k]] = false;
    checkSampler({"split: far lights", [&](Rng& rng) { return tree.sampleFar(sp, near, rng); },
                  [&](std::uint32_t i) { return tree.pdfFar(sp, near, i); }},
                 N, litFar);
    // restir's light tiles: a uniform entry of a random tile, over fresh
    // presamplings (4 tiles of 8 lights each draw, every one a new frame), is
    // drawn with the power pmf, the pdf a candidate reports.
    std::uint32_t frame = 0;
    checkSampler({"candidates: light tiles",
                  [&](Rng& rng) {
                      const LightTiles tiles = presampleLightTiles(power, 4, 8, frame++, 21, nullptr);
                      return tiles.sample(rng.uniformInt(tiles.count), rng);
                  },
                  [&](std::uint32_t i) { return sourcePdf<true>(L, &power, i); }},
                 N, emits);
}

TEST_CASE("split's far cut, found at a particle's centre, draws in proportion to pdfFar at every pixel on it",
          "[lighting][sampler][statistical]") {
    // The renderer finds a particle's near field and far cut once, at its
    // centre with its billboard normal, and draws far lights for each of its
    // pixels at the pixel's own point (and, for sphere impostors, normal).
    Settings s = accretion::test::smallDiskSettings();
    s.particles.count = 4000;  // enough lights for cut nodes above the gather size
    const Particles particles = ParticleSource(s).frame(0);
    const auto N = static_cast<std::uint32_t>(particles.size());
    const LightArrays L{particles, s.shading};
    const LightTree tree(particles, s.shading);
    const std::uint32_t j = 1234;
    const Vec3 n = glm::normalize(Vec3(0.3f, 1.0f, 0.2f));
    const ShadingPoint centre{particles.position[j], n, n, Vec3(0.8f), j, particles.position[j], Vec3(0.0f)};
    // A point on the billboard's plane half a radius from the centre, seen
    // with the billboard's normal and with a tilted (impostor) one.
    const Vec3 along = glm::normalize(glm::cross(n, Vec3(1, 0, 0)));
    const Vec3 local = 0.5f * particles.radius[j] * along;
    ShadingPoint flat = centre;
    flat.x += local;
    flat.local = local;
    ShadingPoint tilted = flat;
    tilted.n = glm::normalize(n + 0.8f * along);
    NearField near;
    for (const std::uint32_t k : {16u, 256u}) {
        INFO("k " << k);
        tree.nearest(centre, k, near, 256);  // the renderer's smallest cut (kMinFarCut)
        // The cut is refined down to single lights, and holds nodes that the
        // draws descend below and gather from.
        std::uint32_t leaves = 0, gathered = 0, descended = 0;
        for (std::uint32_t c = 0; c < near.cutCount; ++c) {
            const std::uint32_t count = tree.nodes()[near.cutNode[c]].count;
            leaves += count == 1;
            gathered += count > 1 && count <= 16;
            descended += count > 16;
        }
        CHECK(leaves > 0);
        CHECK(gathered > 0);
        CHECK(descended > 0);
        for (const ShadingPoint* sp : {&flat, &tilted}) {
            std::vector<bool> lit(N);
            for (std::uint32_t i = 0; i < N; ++i) {
                LightTerm t;
                lit[i] = !near.contains(i) && L.term<ShadingModel::lambert>(*sp, i, t);
            }
            checkSampler({sp == &flat ? "split: a pixel on the billboard" : "split: a pixel with a tilted normal",
                          [&](Rng& rng) { return tree.sampleFar(*sp, near, rng); },
                          [&](std::uint32_t i) { return tree.pdfFar(*sp, near, i); }},
                         N, lit);
        }
    }
}

TEST_CASE("ReGIR cell reservoirs: W is an unbiased estimate of 1 / p_src for every light", "[lighting][sampler][statistical]") {
    // A regir candidate carries its slot's W in place of 1 / p_src. RIS then
    // stays unbiased iff E[W 1{y = i}] = 1 for every light i that can light a
    // receiver in the cell. Over B fresh grids, per slot of the receiver's
    // cell: (a) sum_i f(i) against the mean of f(y) W, f the receiver's
    // unshadowed luminance; (b) the light count against the mean of W; (c)
    // each of 6 groups of lights by index against E[W 1{y in group}] = its size.
    // |z| < 4.4 (p ~ 1e-5 each); each test resolves a 5% bias (5.4 stderr below
    // 5% of the expectation), and a grid of W = w_sum / M (without the 1 / p_hat
    // of the contribution weight) fails them.
    const SamplerScene scene;
    const auto& [s, particles, N, L, power, sp] = scene;
    std::vector<double> f(N, 0.0);
    double fTotal = 0.0, emitting = 0.0;
    std::vector<double> groupSize(6, 0.0);
    for (std::uint32_t i = 0; i < N; ++i) {
        LightTerm t;
        if (L.term<ShadingModel::lambert>(sp, i, t)) f[i] = luminance(t.value);
        fTotal += f[i];
        if (luminance(particles.emission[i]) > 0.0f) {
            emitting += 1.0;
            groupSize[i % 6] += 1.0;
        }
    }
    const std::uint32_t builds = 5000, slots = 64;
    // One estimate per build (the mean over the cell's slots), per statistic.
    std::vector<std::vector<double>> est(8, std::vector<double>(builds, 0.0));
    for (const bool broken : {false, true}) {
        for (std::uint32_t b = 0; b < builds; ++b) {
            const LightTiles tiles = presampleLightTiles(power, 4, 64, b, 5, nullptr);
            RegirGrid g = presampleRegirGrid(L, tiles, RegirPlacement{2, 0.0f}, slots, 8, b, 5, nullptr);
            const std::int64_t cell = g.cellOf(sp.x);
            REQUIRE(cell >= 0);
            for (auto& e : est) e[b] = 0.0;
            for (std::uint32_t k = 0; k < slots; ++k) {
                const std::size_t slot = std::size_t(cell) * slots + k;
                if (g.W[slot] <= 0.0f) continue;
                const std::uint32_t y = g.light[slot];
                double W = g.W[slot];
                if (broken) W *= g.cellTarget(L, std::uint32_t(cell), y);  // w_sum / M: no 1 / p_hat(y)
                est[0][b] += f[y] * W / slots;
                est[1][b] += W / slots;
                est[2 + y % 6][b] += W / slots;
            }
        }
        std::vector<double> expected{fTotal, emitting};
        expected.insert(expected.end(), groupSize.begin(), groupSize.end());
        bool anyFar = false;
        for (std::size_t k = 0; k < est.size(); ++k) {
            double m = 0.0, m2 = 0.0;
            for (const double x : est[k]) {
                m += x;
                m2 += x * x;
            }
            m /= builds;
            const double se = std::sqrt(std::max(0.0, (m2 / builds - m * m) / (builds - 1.0)));
            const double z = (m - expected[k]) / se;
            INFO("broken " << broken << ", statistic " << k << ": mean " << m << " +- " << se << ", expected " << expected[k] << ", z " << z);
            if (!broken) {
                CHECK(std::fabs(z) < 4.4);
                CHECK(5.4 * se < 0.05 * expected[k]);
            }
            anyFar = anyFar || std::fabs(z) > 4.4;
        }
        if (broken) CHECK(anyFar);
    }
}

TEST_CASE("SourcePmf (the GPU twin's sampler) with PortableRng draws sampleSource's lights and pdfs", "[lighting][sampler]") {
    Settings s = accretion::test::smallDiskSettings();
    s.particles.count = 1000;
    Particles particles = ParticleSource(s).frame(0);
    const LightArrays L(particles, s.shading);
    const AliasTable power = buildPowerTable(particles);
    for (const bool usePower : {false, true}) {
        INFO("power " << usePower);
        const SourcePmf pmf{usePower, usePower ? power.view() : AliasTableView{}, L.count, L.uniformPdf};
        std::uint32_t differing = 0, powerMass = 0;
        for (std::uint64_t px = 0; px < 64; ++px) {
            Rng cpu(px, 3, RngPass::lightSampling, 5, 2);
            PortableRng gpu(px, 3, RngPass::lightSampling, 5, 2);
            for (int k = 0; k < 200; ++k) {
                const LightSample a = usePower ? sampleSource<true>(L, &power, cpu) : sampleSource<false>(L, nullptr, cpu);
                const LightSample b = pmf.sample(gpu);
                differing += a.i != b.i || a.pdf != b.pdf;
                powerMass += b.pdf != L.uniformPdf;
            }
        }
        CHECK(differing == 0);
        // The power table's pdf is not the uniform one: the two paths were both exercised.
        CHECK((powerMass > 0) == usePower);
    }
}
