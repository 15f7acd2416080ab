// particle_split, seed 004's hybrid compute (docs/MODEL.md section 4b,
// docs/designs.md): the near search against brute force, a texel lit by
// every light in closed form, the far draws unbiased against a brute-force
// sum that shares nothing with the renderer (the near lights' ball taken
// out of the tree), and the texels' history unbiased with less variance.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include "accretion/analysis/experiment.h"
#include "accretion/geometry/billboard.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/particle_split_passes.h"
#include "accretion/render/particle_texels.h"
#include "support/statistics.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

/// Lr at point x of particle j (its centre by default) from every other
/// particle, by MODEL.md's formula written out here: isotropic, f = rho /
/// (4 pi), no visibility; lambert, f = rho / pi with max(0, n . w), n given.
DVec3 bruteForceLr(const Particles& ps, std::uint32_t j, const Settings& s, const Vec3& n, const DVec3* at = nullptr) {
    const double dmin = s.shading.dmin;
    const DVec3 x = at ? *at : DVec3(ps.position[j]);
    DVec3 sum(0.0);
    for (std::uint32_t i = 0; i < ps.size(); ++i) {
        if (i == j) continue;
        const DVec3 d = DVec3(ps.position[i]) - x;
        const double d2 = glm::dot(d, d);
        double g = 1.0 / std::max(d2, std::max(dmin * dmin, 1e-30));
        if (s.shading.model == ShadingModel::lambert) g *= std::max(0.0, glm::dot(DVec3(n), d / std::sqrt(d2))) * 4.0;
        sum += DVec3(ps.emission[i]) * g;
    }
    return DVec3(s.shading.albedo) * sum / (4.0 * 3.14159265358979323846);
}

/// The particle_split settings of these tests: 1x1 texels (the texel is the
/// particle's centre), visibility off (the brute force has none).
Settings splitSettings(ShadingModel model, std::uint32_t count, std::uint32_t near, std::uint32_t far) {
    Settings s = test::smallDiskSettings();
    s.particles.count = count;
    s.camera.width = 96;
    s.camera.height = 64;
    s.shading.model = model;
    s.shading.visibility = false;
    s.render.estimator = EstimatorKind::particle_split;
    s.particle_split.near = near;
    s.particle_split.far = far;
    s.particle_split.texels = 1;
    return s;
}

/// Each visible particle's Lr in one frame (its pixels agree for 1x1 texels) and the normal it was shaded with.
std::map<std::uint32_t, std::pair<DVec3, Vec3>> particleLr(const FrameImage& img) {
    std::map<std::uint32_t, std::pair<DVec3, Vec3>> out;
    for (std::size_t px = 0; px < img.particle.size(); ++px)
        if (img.particle[px] != kNoParticle) out[img.particle[px]] = {DVec3(img.lighting.Lr[px]), img.normal[px]};
    return out;
}

}  // namespace

TEST_CASE("particle_split: nearestLights on the light tree is the brute-force k nearest, nearest first", "[particle_split]") {
    const test::DiskLights d(ShadingModel::lambert, 3000);
    const LightTreeView view = d.tree.view();
    const std::vector<std::uint64_t> paths = d.tree.paths();
    for (const std::uint32_t k : {1u, 7u, 16u, 64u}) {
        for (std::uint32_t j = 0; j < d.particles.size(); j += 37) {
            std::vector<std::pair<float, std::uint32_t>> all;
            for (std::uint32_t i = 0; i < d.particles.size(); ++i) {
                if (i == j) continue;
                const Vec3 delta = d.particles.position[i] - d.particles.position[j];
                all.push_back({glm::dot(delta, delta), i});
            }
            std::sort(all.begin(), all.end());
            std::uint32_t light[psplit::kMaxNear];
            float d2[psplit::kMaxNear];
            INFO("k " << k << " particle " << j);
            // Started below its own path's node, and below the leftmost path's (any start is exact).
            for (const std::uint64_t path : {paths[j], std::uint64_t(0)}) {
                const std::uint32_t n = psplit::nearestLights(view, d.particles.position[j], j, path, k, light, d2);
                REQUIRE(n == k);
                for (std::uint32_t m = 0; m < n; ++m) {
                    CHECK(light[m] == all[m].second);
                    CHECK(d2[m] == all[m].first);
                }
            }
        }
    }
    // The tree holds fewer lights than asked: all of them but the receiver.
    const test::DiskLights few(ShadingModel::lambert, 10);
    std::uint32_t light[psplit::kMaxNear];
    float d2[psplit::kMaxNear];
    REQUIRE(psplit::nearestLights(few.tree.view(), few.particles.position[3], 3, few.tree.paths()[3], 64, light, d2) == 9);
    REQUIRE_FALSE(psplit::isNear(light, 9, 3));
}

TEST_CASE("particle_split: the near search's visitor sees each node it reads: all 2L - 1 when nothing can be pruned", "[particle_split]") {
    // k above the other lights' count: the k-th distance never prunes, so
    // the search reads every node of the tree once (L leaves, L - 1 inner
    // nodes), its own leaf too.
    const test::DiskLights few(ShadingModel::lambert, 10);
    std::uint32_t light[psplit::kMaxNear];
    float d2[psplit::kMaxNear];
    std::uint32_t leaves = 0, inner = 0, sifts = 0;
    const auto count = [&](psplit::SearchStep step) {
        ++(step == psplit::SearchStep::leaf ? leaves : step == psplit::SearchStep::inner ? inner : sifts);
    };
    REQUIRE(psplit::nearestLights(few.tree.view(), few.particles.position[3], 3, few.tree.paths()[3], 64, light, d2, count) == 9);
    CHECK(leaves == 10);
    CHECK(inner == 9);
    CHECK(sifts > 0);
    // One near light: a heap of one entry never swaps.
    leaves = inner = sifts = 0;
    REQUIRE(psplit::nearestLights(few.tree.view(), few.particles.position[3], 3, few.tree.paths()[3], 1, light, d2, count) == 1);
    CHECK(sifts == 0);
    CHECK(leaves >= 1);
    // 3000 lights, k = 16: pruned, yet every near light was a leaf it read.
    const test::DiskLights d(ShadingModel::lambert, 3000);
    for (std::uint32_t j = 0; j < d.particles.size(); j += 301) {
        leaves = inner = sifts = 0;
        REQUIRE(psplit::nearestLights(d.tree.view(), d.particles.position[j], j, d.tree.paths()[j], 16, light, d2, count) == 16);
        CHECK(leaves >= 16);
        CHECK(leaves + inner < 2 * 3000 - 1);
    }
}

TEST_CASE("particle_split: findNearLights is counted as its search ran: a trip a node read and a heap swap", "[particle_split][gpu]") {
    // 40 particles and 64 near lights: each visible particle's search reads
    // all 2 x 40 - 1 nodes of the frame's light tree (a trip each), plus a
    // trip per swap of its heap, which the same search over the same
    // particles' tree reports to a visitor of the test's.
    Settings s = splitSettings(ShadingModel::lambert, 40, 64, 1);
    s.gpu.counters = true;
    const Particles ps = ParticleSource(s).frame(0);
    const FrameImage img = test::renderParticles(s, ps);
    const auto near = std::find_if(img.counters.passes.begin(), img.counters.passes.end(),
                                   [](const PassCounters& pc) { return pc.pass == Pass::findNearLights; });
    REQUIRE(near != img.counters.passes.end());
    std::set<std::uint32_t> visible(img.particle.begin(), img.particle.end());
    visible.erase(kNoParticle);
    REQUIRE(near->threads.size() == visible.size());
    const test::DiskLights same(ShadingModel::lambert, 40);
    REQUIRE(same.particles.position == ps.position);
    const std::vector<std::uint64_t> paths = same.tree.paths();
    std::vector<std::uint32_t> expected, counted;
    for (const std::uint32_t j : visible) {
        std::uint32_t light[psplit::kMaxNear], reads = 0, sifts = 0;
        float d2[psplit::kMaxNear];
        psplit::nearestLights(same.tree.view(), ps.position[j], j, paths[j], 64, light, d2,
                              [&](psplit::SearchStep step) { ++(step == psplit::SearchStep::sift ? sifts : reads); });
        REQUIRE(reads == 2 * 40 - 1);
        expected.push_back(reads + sifts);
    }
    for (const ThreadCounters& t : near->threads) counted.push_back(t.trips);
    std::sort(expected.begin(), expected.end());
    std::sort(counted.begin(), counted.end());
    CHECK(counted == expected);
}

TEST_CASE("particle_split: FarImportance never takes out a node that holds a light outside the near lights' ball", "[particle_split]") {
    const test::DiskLights d(ShadingModel::lambert, 3000);
    const LightTreeView view = d.tree.view();
    std::uint32_t insideNodes = 0;
    for (std::uint32_t j = 0; j < d.particles.size(); j += 101) {
        std::uint32_t light[psplit::kMaxNear];
        float d2[psplit::kMaxNear];
        const std::uint32_t n = psplit::nearestLights(view, d.particles.position[j], j, d.tree.paths()[j], 32, light, d2);
        const psplit::FarImportance imp{d.particles.position[j], psplit::innerRadius2(d2[n - 1])};
        // Every node taken out holds near lights (or the receiver) alone.
        for (std::uint32_t node = 0; node < view.nodeCount; ++node) {
            if (!imp.inside(view.nodes[node])) continue;
            ++insideNodes;
            std::vector<std::uint32_t> stack{node};
            while (!stack.empty()) {
                const LightTreeNode& m = view.nodes[stack.back()];
                stack.pop_back();
                if (m.count > 1) {
                    stack.push_back(m.child);
                    stack.push_back(m.child + 1);
                    continue;
                }
                INFO("particle " << j << " node " << node << " light " << m.child);
                REQUIRE((m.child == j || psplit::isNear(light, n, m.child)));
            }
        }
    }
    REQUIRE(insideNodes > 100);  // the test has power: the ball takes out subtrees
}

TEST_CASE("particle_split: with every light near, a texel's Lr is the closed-form sum over all of them", "[particle_split]") {
    for (const ShadingModel model : {ShadingModel::isotropic, ShadingModel::lambert}) {
        const Settings s = splitSettings(model, 60, 64, 0);  // 59 others: all near, no far draw
        const Particles ps = ParticleSource(s).frame(0);
        const auto lit = particleLr(test::renderParticles(s, ps));
        REQUIRE(lit.size() > 20);
        for (const auto& [j, v] : lit) {
            const DVec3 expect = bruteForceLr(ps, j, s, v.second);
            INFO(enumName(model) << " particle " << j);
            for (int c = 0; c < 3; ++c) CHECK(v.first[c] == Approx(expect[c]).epsilon(1e-4));
        }
    }
}

TEST_CASE("particle_split: near sum and far draws are unbiased against the brute-force sum (99.99% per particle)", "[particle_split][statistical]") {
    // 400 lights: a near field of 8 or none, far draws from the tree with the
    // ball taken out, each the draw itself or the one RIS keeps among 4. Over 400 seeds each particle's mean is within 4.5
    // standard errors (and 1e-5 of float rounding) of its brute-force Lr (a per-particle chance of about
    // 1e-5 to fail when unbiased), and the frame's total within 4 of its own.
    struct Case {
        ShadingModel model;
        std::uint32_t near, candidates;
    };
    for (const auto& [model, near, candidates] : {Case{ShadingModel::isotropic, 8, 1}, Case{ShadingModel::lambert, 8, 1},
                                                  Case{ShadingModel::lambert, 0, 1}, Case{ShadingModel::lambert, 8, 4}}) {
        Settings s = splitSettings(model, 400, near, 2);
        s.particle_split.candidates = candidates;
        const Particles ps = ParticleSource(s).frame(0);
        const int kSeeds = int(test::statisticalSeeds(400, 50));
        std::map<std::uint32_t, std::pair<DVec3, DVec3>> sums;  // sum, sum of squares (luminance in x)
        std::map<std::uint32_t, Vec3> normal;
        for (int k = 0; k < kSeeds; ++k) {
            s.render.seed = 1000 + k;
            for (const auto& [j, v] : particleLr(test::renderParticles(s, ps))) {
                auto& [sum, sq] = sums[j];
                sum += v.first;
                sq += v.first * v.first;
                normal[j] = v.second;
            }
        }
        REQUIRE(sums.size() > 100);
        double total = 0.0, totalExpect = 0.0, totalVar = 0.0;
        for (const auto& [j, ss] : sums) {
            const DVec3 mean = ss.first / double(kSeeds);
            const DVec3 var = glm::max(DVec3(0.0), ss.second / double(kSeeds) - mean * mean) / double(kSeeds - 1);
            const DVec3 expect = bruteForceLr(ps, j, s, normal[j]);
            INFO(enumName(model) << " near " << near << " candidates " << candidates << " particle " << j << " mean " << mean.y << " expected " << expect.y
                                 << " stderr " << std::sqrt(var.y));
            CHECK(std::abs(mean.y - expect.y) <= 4.5 * std::sqrt(var.y) + 1e-5 * expect.y);
            total += mean.y;
            totalExpect += expect.y;
            totalVar += var.y;
        }
        INFO(enumName(model) << " near " << near << " candidates " << candidates << ": total " << total << " expected " << totalExpect);
        CHECK(std::abs(total - totalExpect) <= 4.0 * std::sqrt(totalVar) + 1e-5 * totalExpect);
    }
}

TEST_CASE("particle_split: the texels' history stays unbiased in a static scene and divides the variance", "[particle_split][statistical]") {
    // h = 0.75 over 12 frames: the steady state's variance is (1 - h) / (1 + h)
    // = 1/7 of one frame's; after 12 frames the first frame weighs 0.75^12 = 3%.
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
    s.particles.gm = 0.0;  // static: the history is the same light
    const Particles ps = ParticleSource(s).frame(0);
    const int kSeeds = int(test::statisticalSeeds(40, 20));
    double varNone = 0.0, varHistory = 0.0, bias = 0.0, biasVar = 0.0;
    std::map<std::uint32_t, std::pair<double, double>> none, history;
    for (int k = 0; k < kSeeds; ++k) {
        Settings a = s, b = s;
        a.render.seed = b.render.seed = 77 + k;
        b.particle_split.history = 0.75;
        b.render.frames = 12;
        FrameRenderer renderer(b, ParticleSource::fixed(ps), RenderOptions{true});
        FrameImage last;
        for (std::uint32_t f = 0; f < 12; ++f) {
            FrameStats st;
            last = renderer.render(f, st);
        }
        for (const auto& [j, v] : particleLr(test::renderParticles(a, ps))) {
            none[j].first += v.first.y;
            none[j].second += v.first.y * v.first.y;
        }
        for (const auto& [j, v] : particleLr(last)) {
            history[j].first += v.first.y;
            history[j].second += v.first.y * v.first.y;
        }
    }
    REQUIRE(history.size() > 100);
    for (const auto& [j, h] : history) {
        const auto& n = none.at(j);
        const double mh = h.first / kSeeds, mn = n.first / kSeeds;
        const double vh = std::max(0.0, h.second / kSeeds - mh * mh), vn = std::max(0.0, n.second / kSeeds - mn * mn);
        varHistory += vh;
        varNone += vn;
        bias += mh - mn;
        biasVar += (vh + vn) / (kSeeds - 1);
    }
    INFO("variance with history " << varHistory << " without " << varNone << "; mean difference " << bias << " +- "
                                  << std::sqrt(biasVar));
    CHECK(varHistory < 0.3 * varNone);  // 1/7 expected; 0.3 leaves room for 20-40 seeds' noise
    CHECK(std::abs(bias) <= 4.0 * std::sqrt(biasVar));  // the same mean: no bias from the average
}

TEST_CASE("particle_split: a jittered texel point is uniform in its square, inside the disc with alpha disc, per frame, "
          "an antithetic one mirrors it in the next frame",
          "[particle_split]") {
    // Pearson chi-square tests at 99.99% (p > 1e-4) over 20000 draws of
    // particles and frames (antithetic: the even frames, whose points are
    // independent): for the square, 4 x 4 equal cells of the texel; for the
    // disc (side 1), r^2 / 0.25 and the angle, each uniform on [0, 1) in 8
    // bins for a uniform point in the disc. Antithetic: the odd frame's
    // point is the even one's mirror about the texel's centre (to rounding).
    for (const TexelPoint mode : {TexelPoint::jittered, TexelPoint::antithetic}) {
        for (const std::uint32_t side : {1u, 2u, 3u}) {
            for (const bool disc : {false, true}) {
                if (disc && side > 1) continue;
                for (std::uint32_t sub = 0; sub < side * side; ++sub) {
                    std::vector<double> cells(16, 0.0), r2(8, 0.0), angle(8, 0.0);
                    const int n = 20000;
                    for (int k = 0; k < n; ++k) {
                        const bool pairs = mode == TexelPoint::antithetic;
                        const int frames = pairs ? 25 : 50;  // each particle's frames (antithetic: the even ones)
                        const std::uint32_t frame = std::uint32_t(k % frames) * (pairs ? 2u : 1u), j = std::uint32_t(k / frames) * 31u + 3u;
                        const TexelPointRule rule{mode, disc, frame, 7};
                        const Vec2 uv = texelPointUv(j, sub, side, rule);
                        const Vec2 c = texelUv(sub, side);
                        if (pairs) {
                            const Vec2 mirror = texelPointUv(j, sub, side, TexelPointRule{mode, disc, frame + 1, 7});
                            INFO("side " << side << " sub " << sub << " disc " << disc << " uv " << uv.x << " " << uv.y << " next frame " << mirror.x << " " << mirror.y);
                            REQUIRE(std::abs(uv.x + mirror.x - 2.0f * c.x) <= 1e-6f);
                            REQUIRE(std::abs(uv.y + mirror.y - 2.0f * c.y) <= 1e-6f);
                            REQUIRE((!disc || insideDisc(mirror)));
                        }
                        const float half = 0.5f / float(side) + 1e-6f;  // the square, closed, and its edges' rounding
                        INFO(enumName(mode) << " side " << side << " sub " << sub << " disc " << disc << " uv " << uv.x << " " << uv.y);
                        REQUIRE(std::abs(uv.x - c.x) <= half);
                        REQUIRE(std::abs(uv.y - c.y) <= half);
                        if (disc) {
                            REQUIRE(insideDisc(uv));
                            const Vec2 d = uv - Vec2(0.5f);
                            r2[std::min(7, int(8.0 * glm::dot(d, d) / 0.25))] += 1.0;
                            angle[std::min(7, int(8.0 * (std::atan2(double(d.y), double(d.x)) / (2.0 * M_PI) + 0.5)))] += 1.0;
                        } else {
                            const float side1 = 1.0f / float(side);
                            const int cx = std::clamp(int(4.0f * (uv.x - c.x) / side1 + 2.0f), 0, 3);
                            const int cy = std::clamp(int(4.0f * (uv.y - c.y) / side1 + 2.0f), 0, 3);
                            cells[cy * 4 + cx] += 1.0;
                        }
                    }
                    INFO(enumName(mode) << " side " << side << " sub " << sub << " disc " << disc);
                    if (disc) {
                        CHECK(test::chiSquarePValue(r2, std::vector<double>(8, n / 8.0)) > 1e-4);
                        CHECK(test::chiSquarePValue(angle, std::vector<double>(8, n / 8.0)) > 1e-4);
                    } else {
                        CHECK(test::chiSquarePValue(cells, std::vector<double>(16, n / 16.0)) > 1e-4);
                    }
                }
            }
        }
    }
    // The centre without jitter; a point of its own per frame and seed with it, the same for the same inputs.
    const TexelPointRule centre{TexelPoint::centre, false, 5, 7};
    CHECK(texelPointUv(9, 3, 2, centre) == texelUv(3, 2));
    for (const TexelPoint mode : {TexelPoint::jittered, TexelPoint::antithetic}) {
            const TexelPointRule a{mode, false, 4, 7}, b{mode, false, 6, 7}, c{mode, false, 4, 8};
            CHECK(texelPointUv(9, 3, 2, a) == texelPointUv(9, 3, 2, a));
            CHECK(texelPointUv(9, 3, 2, a) != texelPointUv(9, 3, 2, b));
            CHECK(texelPointUv(9, 3, 2, a) != texelPointUv(9, 3, 2, c));
    }
}

TEST_CASE("particle_split: jittered and antithetic texels are unbiased for the light averaged over the billboard, not at its centre",
          "[particle_split][statistical]") {
    // 400 lights, 1x1 texels on opaque billboards made large (radius 0.4,
    // about the lights' spacing, so that the light varies across them),
    // isotropic, no visibility, no history: over 400 seeds (frames of their
    // own) each particle's mean is within 4.5 standard errors of the
    // brute-force Lr averaged over its billboard square (a 64 x 64 midpoint
    // rule; its own error bounded by the change from 32 x 32), the frame's
    // total within 4 of its own. The centre's Lr, what texel_point centre
    // estimates, is told apart: the sum over the N particles of its squared
    // z-scores exceeds N + 10 sqrt(2 N), a chi-square of N degrees of freedom
    // (which the area mean's z-scores are) far in its tail. Antithetic
    // alternates frames 0 and 1, the point and its mirror (of another seed's).
    Settings s = splitSettings(ShadingModel::isotropic, 400, 8, 2);
    s.particles.radius = 0.4;
    s.particles.radius_jitter = 0.0;
    s.particle_split.candidates = 4;
    REQUIRE(s.geometry.orientation == Orientation::view_plane);  // the billboards span the camera's right and up
    const test::TracedFrame traced(s);
    const Particles& ps = traced.particles;
    const DVec3 right(traced.camera.right), up(traced.camera.up);
    const int kSeeds = int(test::statisticalSeeds(400, 50));
    // Each particle's area mean at 64 x 64 and 32 x 32, once for both modes
    // (the brute-force sums are most of the test's time).
    std::map<std::uint32_t, std::pair<double, double>> areaMeans;
    for (const TexelPoint mode : {TexelPoint::jittered, TexelPoint::antithetic}) {
    s.particle_split.texel_point = mode;
    std::map<std::uint32_t, std::pair<double, double>> sums;  // luminance: sum, sum of squares
    for (int k = 0; k < kSeeds; ++k) {
        s.render.seed = 3000 + k;
        const std::uint32_t frame = mode == TexelPoint::antithetic ? std::uint32_t(k % 2) : 0u;
        for (const auto& [j, v] : particleLr(test::renderParticles(s, ps, frame))) {
            sums[j].first += v.first.y;
            sums[j].second += v.first.y * v.first.y;
        }
    }
    REQUIRE(sums.size() > 100);
    const auto areaMean = [&](std::uint32_t j, int n) {
        double sum = 0.0;
        for (int a = 0; a < n; ++a)
            for (int b = 0; b < n; ++b) {
                const double u = (a + 0.5) / n, v = (b + 0.5) / n, r = ps.radius[j];
                const DVec3 x = DVec3(ps.position[j]) + (2.0 * u - 1.0) * r * right + (2.0 * v - 1.0) * r * up;
                sum += bruteForceLr(ps, j, s, Vec3(0.0f, 0.0f, 1.0f), &x).y;
            }
        return sum / (double(n) * n);
    };
    double total = 0.0, totalExpect = 0.0, totalVar = 0.0;
    double centreZ2 = 0.0, areaZ2 = 0.0;
    for (const auto& [j, ss] : sums) {
        const double mean = ss.first / kSeeds;
        const double var = std::max(0.0, ss.second / kSeeds - mean * mean) / (kSeeds - 1);
        auto known = areaMeans.find(j);
        if (known == areaMeans.end()) known = areaMeans.emplace(j, std::pair{areaMean(j, 64), areaMean(j, 32)}).first;
        const double expect = known->second.first, quadrature = std::abs(expect - known->second.second);
        const double centre = bruteForceLr(ps, j, s, Vec3(0.0f, 0.0f, 1.0f)).y;
        INFO("particle " << j << " mean " << mean << " area mean " << expect << " (quadrature " << quadrature << ") centre " << centre
                         << " stderr " << std::sqrt(var));
        CHECK(std::abs(mean - expect) <= 4.5 * std::sqrt(var) + quadrature + 1e-5 * expect);
        centreZ2 += (mean - centre) * (mean - centre) / var;
        areaZ2 += (mean - expect) * (mean - expect) / var;
        total += mean;
        totalExpect += expect;
        totalVar += var;
    }
    const double N = double(sums.size());
    INFO(enumName(mode) << ": total " << total << " expected " << totalExpect << "; squared z-scores summed over " << N << " particles: " << areaZ2
                  << " from the area means, " << centreZ2 << " from the centres");
    CHECK(std::abs(total - totalExpect) <= 4.0 * std::sqrt(totalVar) + 1e-5 * totalExpect);
    CHECK(areaZ2 < N + 6.0 * std::sqrt(2.0 * N));
    CHECK(centreZ2 > N + 10.0 * std::sqrt(2.0 * N));
    }
}

TEST_CASE("particle_split: its frame runs its own passes, not restir's", "[particle_split][plan]") {
    Settings s = splitSettings(ShadingModel::lambert, 400, 8, 4);
    s.shading.visibility = true;
    const FramePlan plan = planFrame(s, FrameFacts{});
    const std::vector<Pass> passes = plan.passes();
    for (const Pass p : {Pass::buildLightSampler, Pass::gatherParticleTexels, Pass::findNearLights, Pass::shadeSplitTexels,
                         Pass::shadeParticlePixels})
        CHECK(std::find(passes.begin(), passes.end(), p) != passes.end());
    for (const Pass p : {Pass::generateCandidates, Pass::temporalResampling, Pass::spatialResampling, Pass::traceShadowRays,
                         Pass::updateVoxelCache})
        CHECK(std::find(passes.begin(), passes.end(), p) == passes.end());
    REQUIRE(plan.sampler == LightSamplerKind::tree);
    // The gather names where its texels lie when not at their centres.
    const auto gatherWhy = [&](TexelPoint point) {
        Settings t = s;
        t.particle_split.texel_point = point;
        return planFrame(t, FrameFacts{}).find(Pass::gatherParticleTexels)->why;
    };
    CHECK_THAT(gatherWhy(TexelPoint::centre), !Catch::Contains("drawn"));
    CHECK_THAT(gatherWhy(TexelPoint::antithetic), Catch::Contains("drawn each frame (antithetic)"));
    // Counting mode: each pass's threads recorded, the texels' shadow rays among them.
    s.gpu.counters = true;
    const Particles ps = ParticleSource(s).frame(0);
    const FrameImage img = test::renderParticles(s, ps);
    std::map<Pass, std::uint64_t> rays;
    for (const PassCounters& pc : img.counters.passes)
        for (const ThreadCounters& t : pc.threads) rays[pc.pass] += t.rays;
    for (const Pass p : {Pass::gatherParticleTexels, Pass::findNearLights, Pass::shadeSplitTexels, Pass::shadeParticlePixels}) {
        INFO(passName(p));
        REQUIRE(rays.count(p) == 1);
    }
    REQUIRE(rays[Pass::shadeSplitTexels] > 0);
    REQUIRE(rays[Pass::findNearLights] == 0);  // the near search traces no ray
    // shadeSplitTexels is counted as the twin runs it: a thread per ray of
    // each texel (the near rays texel by texel, then the far ones), each
    // tracing at most its one shadow ray, and the per-texel sum's dispatch.
    const auto texels = std::find_if(img.counters.passes.begin(), img.counters.passes.end(),
                                     [](const PassCounters& pc) { return pc.pass == Pass::shadeSplitTexels; });
    REQUIRE(texels->height == s.particle_split.near + s.particle_split.far);
    CHECK(texels->dispatches == 2);
    // One texel a visible particle (the particles the image shows), in rows of kTexelRowWidth.
    std::set<std::uint32_t> visible;
    for (const std::uint32_t j : img.particle)
        if (j != kNoParticle) visible.insert(j);
    REQUIRE(!visible.empty());
    CHECK(texels->width == (visible.size() + kTexelRowWidth - 1) / kTexelRowWidth * kTexelRowWidth);
    std::uint64_t most = 0, pastTexels = 0;
    const std::size_t nearThreads = std::size_t(texels->width) * s.particle_split.near;
    for (std::size_t k = 0; k < texels->threads.size(); ++k) {
        most = std::max<std::uint64_t>(most, texels->threads[k].rays);
        const std::size_t texel = k < nearThreads ? k / s.particle_split.near : (k - nearThreads) / s.particle_split.far;
        if (texel >= visible.size()) pastTexels += texels->threads[k].rays;  // the last row's tail: no texel
    }
    CHECK(most == 1);
    CHECK(pastTexels == 0);
    // gatherParticleTexels' kernels beside its pixels, from the image's own
    // visible set: 2 per particle (ids, select), 11 per visible particle
    // (key, slot, the sort's histogram and 8 digit passes), 1 per texel of
    // the grid (kTexelRowWidth a row, one texel a particle here), in 18
    // dispatches (2 memsets, 16 kernels).
    const auto gather = std::find_if(img.counters.passes.begin(), img.counters.passes.end(),
                                     [](const PassCounters& pc) { return pc.pass == Pass::gatherParticleTexels; });
    REQUIRE(gather != img.counters.passes.end());
    const std::uint64_t gridTexels = (visible.size() + kTexelRowWidth - 1) / kTexelRowWidth * kTexelRowWidth;
    CHECK(gather->itemSteps == 2 * ps.size() + 11 * visible.size() + gridTexels);
    CHECK(gather->dispatches == 18);
    for (const PassCounters& pc : img.counters.passes)
        if (pc.pass != Pass::gatherParticleTexels) CHECK(pc.itemSteps == 0);
}

TEST_CASE("particle_split: the ray threads' order visits every ray of every texel once, near before far, and inverts", "[particle_split]") {
    // shadeSplitTexels' threads (the twin's launch, the CPU's counting
    // records): a bijection of (texel, ray) onto [0, texels x rays), every
    // near ray before every far one, a texel's rays of one kind side by side.
    for (const auto [near, far] : {std::pair{8u, 4u}, std::pair{16u, 8u}, std::pair{1u, 0u}, std::pair{0u, 3u}, std::pair{32u, 16u}}) {
        psplit::SplitParams p;
        p.nearCount = near;
        p.farSamples = far;
        const std::size_t texels = 24, rays = near + far;
        INFO("near " << near << ", far " << far);
        std::vector<int> seen(texels * rays, 0);
        for (std::size_t q = 0; q < texels; ++q)
            for (std::uint32_t r = 0; r < rays; ++r) {
                const std::size_t L = psplit::splitRayThread(p, texels, q, r);
                REQUIRE(L < seen.size());
                ++seen[L];
                CHECK((L < texels * near) == (r < near));
                if (r > 0 && (r < near) == (r - 1 < near)) CHECK(L == psplit::splitRayThread(p, texels, q, r - 1) + 1);
                const psplit::SplitRayOfThread back = psplit::splitRayOfThread(p, texels, L);
                CHECK(back.texel == q);
                CHECK(back.ray == r);
            }
        CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(seen.size()));
    }
}

TEST_CASE("particle_split: history_of far averages the far mean alone, the near sum being the frame's own", "[particle_split]") {
    // Frames 0-5 of each configuration's sequence, the last one compared.
    const auto lastFrame = [](const Settings& s, const ParticleSource& source) {
        FrameRenderer renderer(s, source, RenderOptions{true});
        FrameImage img;
        for (std::uint32_t f = 0; f < 6; ++f) {
            FrameStats st;
            img = renderer.render(f, st);
        }
        return img;
    };
    SECTION("a static scene: the same light, so near + the far mean's average is the average of both, to rounding") {
        // Lr_t = (1 - h) (N + F_t) + h Lr_t-1 with Lr_0 = N + F_0 is N + Fbar_t,
        // Fbar_t = (1 - h) F_t + h Fbar_t-1, Fbar_0 = F_0: the same draws give the same image.
        Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
        s.shading.visibility = true;
        s.particles.gm = 0.0;
        s.particle_split.history = 0.8;
        s.render.frames = 6;
        const ParticleSource source(s);
        Settings far = s;
        far.particle_split.history_of = HistoryOf::far;
        const FrameImage a = lastFrame(s, source), b = lastFrame(far, source);
        std::size_t lit = 0;
        for (std::size_t px = 0; px < a.lighting.Lr.size(); ++px) {
            if (a.particle[px] == kNoParticle) continue;
            ++lit;
            for (int c = 0; c < 3; ++c)
                REQUIRE(b.lighting.Lr[px][c] == Approx(a.lighting.Lr[px][c]).epsilon(1e-5).margin(1e-9));
        }
        CHECK(lit > 500);
    }
    SECTION("a rotating disk, near lights only: history_of far is the frame without history, bit for bit; all lags") {
        Settings s = splitSettings(ShadingModel::lambert, 400, 8, 0);
        s.shading.visibility = true;
        s.render.frames = 6;
        const ParticleSource source(s);
        Settings all = s, far = s;
        all.particle_split.history = far.particle_split.history = 0.9;
        far.particle_split.history_of = HistoryOf::far;
        const FrameImage none = lastFrame(s, source), a = lastFrame(all, source), b = lastFrame(far, source);
        std::size_t lit = 0, lagging = 0;
        for (std::size_t px = 0; px < none.lighting.Lr.size(); ++px) {
            if (none.particle[px] == kNoParticle) continue;
            ++lit;
            REQUIRE(b.lighting.Lr[px] == none.lighting.Lr[px]);
            lagging += a.lighting.Lr[px] != none.lighting.Lr[px];
        }
        CHECK(lit > 500);
        CHECK(lagging > lit / 2);
    }
}

TEST_CASE("particle_split: history_start mean is the running mean of a texel's frames, then the exponential average",
          "[particle_split]") {
    // A static scene: every frame's texel is a fresh estimate x_f of one
    // light (the frame's own draws, as a render without history makes
    // them). With h = 0.9 four frames are their mean (x0 + x1 + x2 + x3) / 4;
    // with h = 0.5 the running mean stops at two frames, 1/n = 1 - h, and the
    // exponential average goes on: ((x0 + x1) / 2 / 2 + x2 / 2) / 2 + x3 / 2.
    // So with history_of all and far alike (the near sum is the same light).
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
    s.shading.visibility = true;
    s.particles.gm = 0.0;
    s.render.frames = 4;
    const ParticleSource source(s);
    const auto frames = [&](const Settings& settings) {
        FrameRenderer renderer(settings, source, RenderOptions{true});
        std::vector<FrameImage> out;
        for (std::uint32_t f = 0; f < 4; ++f) {
            FrameStats st;
            out.push_back(renderer.render(f, st));
        }
        return out;
    };
    const std::vector<FrameImage> fresh = frames(s);
    for (const HistoryOf of : {HistoryOf::all, HistoryOf::far})
        for (const double h : {0.9, 0.5}) {
            INFO("history_of " << enumName(of) << ", h = " << h);
            Settings m = s;
            m.particle_split.history = h;
            m.particle_split.history_of = of;
            m.particle_split.history_start = HistoryStart::mean;
            const FrameImage last = frames(m).back();
            std::size_t lit = 0;
            for (std::size_t px = 0; px < last.lighting.Lr.size(); ++px) {
                if (last.particle[px] == kNoParticle) continue;
                ++lit;
                for (int c = 0; c < 3; ++c) {
                    double x[4];
                    for (int f = 0; f < 4; ++f) x[f] = fresh[f].lighting.Lr[px][c];
                    const double expected = h == 0.9 ? (x[0] + x[1] + x[2] + x[3]) / 4.0
                                                     : 0.5 * (0.5 * (x[0] + x[1]) / 2.0 + 0.5 * x[2]) + 0.5 * x[3];
                    REQUIRE(double(last.lighting.Lr[px][c]) == Approx(expected).epsilon(1e-5).margin(1e-9));
                }
            }
            CHECK(lit > 500);
        }
}

TEST_CASE("particle_split: far_new's extra rays are threads past every texel's own, in the order of their texels, and invert",
          "[particle_split]") {
    // With a history, the texels without one (here every third) draw far_new
    // far rays: their extra rays' threads follow every texel's near and far
    // rays, texel by texel in the select's order; the whole launch is a
    // bijection onto [0, texels x (near + far) + new texels x extra).
    for (const auto [near, far, farNew] : {std::tuple{8u, 4u, 16u}, std::tuple{16u, 8u, 9u}, std::tuple{1u, 0u, 3u}}) {
        psplit::SplitParams p;
        p.nearCount = near;
        p.farSamples = far;
        p.farNew = farNew;
        p.history = 0.9f;
        const std::uint32_t extra = psplit::extraNewRays(p);
        REQUIRE(extra == farNew - far);
        const std::size_t texels = 24;
        std::vector<std::uint32_t> newTexels, newIndex(texels, kNoSlot);
        for (std::size_t q = 0; q < texels; q += 3) {
            newIndex[q] = std::uint32_t(newTexels.size());
            newTexels.push_back(std::uint32_t(q));
        }
        INFO("near " << near << ", far " << far << ", far_new " << farNew);
        std::vector<int> seen(texels * (near + far) + newTexels.size() * extra, 0);
        for (std::size_t q = 0; q < texels; ++q)
            for (std::uint32_t r = 0; r < near + far + (newIndex[q] != kNoSlot ? extra : 0); ++r) {
                const std::size_t L = psplit::splitRayThread(p, texels, q, r, r >= near + far ? newIndex[q] : 0);
                REQUIRE(L < seen.size());
                ++seen[L];
                CHECK((L >= texels * (near + far)) == (r >= near + far));
                const psplit::SplitRayOfThread back = psplit::splitRayOfThread(p, texels, L, newTexels.data());
                CHECK(back.texel == q);
                CHECK(back.ray == r);
            }
        CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(seen.size()));
        // Without a history no texel has one to lack: no extra rays.
        p.history = 0.0f;
        CHECK(psplit::extraNewRays(p) == 0);
    }
}

TEST_CASE("particle_split: far_new draws a new texel's far rays as a render with far = far_new would, then weighs them as frames",
          "[particle_split]") {
    // A static scene. Frame 0: every texel is new and draws F = far_new far
    // rays, from the streams a render without history and far = F draws: the
    // same image, bit for bit. Later frames draw S = far, and with
    // history_start mean the texel is the mean of all its far rays: at frame
    // 2, (F x A0 + S x B1 + S x B2) / (F + 2 S), A0 the render with far = F
    // and B the one with far = S (the near sum is the same light in all).
    const std::uint32_t S = 2, F = 8;
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, S);
    s.shading.visibility = true;
    s.particles.gm = 0.0;
    s.render.frames = 3;
    const ParticleSource source(s);
    const auto frames = [&](const Settings& settings) {
        FrameRenderer renderer(settings, source, RenderOptions{true});
        std::vector<FrameImage> out;
        for (std::uint32_t f = 0; f < 3; ++f) {
            FrameStats st;
            out.push_back(renderer.render(f, st));
        }
        return out;
    };
    Settings wide = s;
    wide.particle_split.far = F;
    const std::vector<FrameImage> narrowFrames = frames(s), wideFrames = frames(wide);
    for (const HistoryOf of : {HistoryOf::all, HistoryOf::far}) {
        INFO("history_of " << enumName(of));
        Settings m = s;
        m.particle_split.history = 0.9;
        m.particle_split.history_of = of;
        m.particle_split.history_start = HistoryStart::mean;
        m.particle_split.far_new = F;
        const std::vector<FrameImage> got = frames(m);
        std::size_t lit = 0;
        for (std::size_t px = 0; px < got[0].lighting.Lr.size(); ++px) {
            if (got[0].particle[px] == kNoParticle) continue;
            ++lit;
            REQUIRE(got[0].lighting.Lr[px] == wideFrames[0].lighting.Lr[px]);
            for (int c = 0; c < 3; ++c) {
                const double expected = (F * double(wideFrames[0].lighting.Lr[px][c]) + S * double(narrowFrames[1].lighting.Lr[px][c]) +
                                         S * double(narrowFrames[2].lighting.Lr[px][c])) / double(F + 2 * S);
                REQUIRE(double(got[2].lighting.Lr[px][c]) == Approx(expected).epsilon(1e-5).margin(1e-9));
            }
        }
        CHECK(lit > 500);
    }
}

TEST_CASE("particle_split: far_new's extra ray threads are those of the particles the last frame did not show", "[particle_split][gpu]") {
    // A rotating disk seen from its side, counted: each frame's
    // shadeSplitTexels launches texels x (near + far) threads plus extra
    // for each texel without history, whose particle, by the two frames'
    // own particle-id images, is visible now and was not last frame. Frame
    // 0 has no history: every visible texel draws them.
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
    s.shading.visibility = true;
    s.gpu.counters = true;
    s.render.frames = 4;
    s.particle_split.history = 0.8;
    s.particle_split.far_new = 10;
    const std::uint32_t extra = 10 - 2;
    const ParticleSource source(s);
    FrameRenderer renderer(s, source, RenderOptions{true});
    std::set<std::uint32_t> last;
    std::size_t enteredTotal = 0;
    for (std::uint32_t f = 0; f < 4; ++f) {
        FrameStats st;
        const FrameImage img = renderer.render(f, st);
        std::set<std::uint32_t> visible;
        for (const std::uint32_t j : img.particle)
            if (j != kNoParticle) visible.insert(j);
        std::size_t entered = 0;
        for (const std::uint32_t j : visible) entered += !last.count(j);
        const auto texels = std::find_if(img.counters.passes.begin(), img.counters.passes.end(),
                                         [](const PassCounters& pc) { return pc.pass == Pass::shadeSplitTexels; });
        REQUIRE(texels != img.counters.passes.end());
        const std::size_t grid = (visible.size() + kTexelRowWidth - 1) / kTexelRowWidth * kTexelRowWidth;
        INFO("frame " << f << ": " << visible.size() << " visible, " << entered << " new");
        CHECK(texels->threads.size() == grid * (4 + 2) + entered * extra);
        CHECK(texels->dispatches == 3);
        // Each extra thread traces at most its one shadow ray, and some do.
        std::uint64_t extraRays = 0, most = 0;
        for (std::size_t k = grid * 6; k < texels->threads.size(); ++k) {
            extraRays += texels->threads[k].rays;
            most = std::max<std::uint64_t>(most, texels->threads[k].rays);
        }
        CHECK(most <= 1);
        if (entered) CHECK(extraRays > 0);
        if (f > 0) enteredTotal += entered;
        last = std::move(visible);
    }
    CHECK(enteredTotal > 0);  // the disk's rotation brought particles into view
}

namespace {

/// sumSplitTexel's bridge over plain arrays: texel q is particle q's (one
/// texel each), its rays the fixed values of `ray`, its near lights
/// `near`, last frame's texels those of `lastSlot` (particle -> texel, or
/// kNoSlot) with far means `lastFar` and ages `lastAge`.
struct PriorBridge {
    psplit::SplitParams p;
    std::vector<std::vector<std::uint32_t>> near;
    std::vector<std::uint32_t> lastSlot;
    std::vector<Vec3> lastFar;
    std::vector<std::uint32_t> lastAge;
    std::vector<std::vector<std::uint32_t>> lastNear;  ///< far_handoff: last frame's near lights by its slots
    std::vector<std::vector<Vec3>> lastNearValue;      ///< and its texels' near terms (a texel a slot here)
    std::vector<Vec3> nearWritten;                     ///< this frame's near terms of the texel summed
    std::vector<Vec3> ray;  ///< ray r's value, every texel
    Vec3 Lr{0.0f}, far{0.0f};
    std::uint32_t age = 0;
    const psplit::SplitParams& params() const { return p; }
    GBufferTexel texel(std::size_t q) const {
        GBufferTexel g;
        g.particle = std::uint32_t(q);
        return g;
    }
    psplit::SplitRay splitRay(std::size_t, std::uint32_t r) const { return {ray[r], 0}; }
    void reject(std::size_t) const {}
    std::uint32_t nearLights(std::uint32_t v, std::uint32_t* light) const {
        std::copy(near[v].begin(), near[v].end(), light);
        return std::uint32_t(near[v].size());
    }
    bool historyTexelOf(std::uint32_t j, std::uint32_t, std::size_t& q) const {
        if (j >= lastSlot.size() || lastSlot[j] == kNoSlot) return false;
        q = lastSlot[j];
        return true;
    }
    Vec3 historyFar(std::size_t q) const { return lastFar[q]; }
    Vec3 historyLr(std::size_t) const { return Vec3(1e9f); }  // never read with history_of far
    std::uint32_t historyAge(std::size_t q) const { return lastAge[q]; }
    void writeTexelAge(std::size_t, std::uint32_t n) { age = n; }
    void writeTexelFar(std::size_t, const Vec3& f) { far = f; }
    void writeTexelLr(std::size_t, const Vec3& L) { Lr = L; }
    std::uint32_t historyNearLights(std::uint32_t v, std::uint32_t* light) const {
        std::copy(lastNear[v].begin(), lastNear[v].end(), light);
        return std::uint32_t(lastNear[v].size());
    }
    Vec3 historyNearValue(std::size_t q, std::uint32_t m) const { return lastNearValue[q][m]; }
    void writeTexelNear(std::size_t, std::uint32_t m, const Vec3& v) {
        if (nearWritten.size() <= m) nearWritten.resize(m + 1);
        nearWritten[m] = v;
    }
};

}  // namespace

TEST_CASE("particle_split: far_prior starts a new texel's far mean from its near lights' far means of last frame, in closed form",
          "[particle_split]") {
    // Near 2, far 2, far_prior 6: texel 0 (particle 0, new) has near lights
    // 5, 6 and 7, of which 5 and 7 were in view with far means a and b. Its
    // far mean is 2/8 of its own rays' mean and 6/8 of (a + b) / 2, its age
    // 8 far rays; its Lr the near sum plus that.
    PriorBridge b;
    b.p.nearCount = 2;
    b.p.farSamples = 2;
    b.p.history = 0.9f;
    b.p.historyOfFar = true;
    b.p.historyMean = true;
    b.p.farPrior = 6;
    b.near = {{5, 6, 7}, {7}, {6}};
    b.lastSlot.assign(8, kNoSlot);
    b.lastSlot[5] = 0;
    b.lastSlot[7] = 1;
    b.lastSlot[1] = 2;  // particle 1 was in view: not new
    b.lastFar = {Vec3(1.0f, 2.0f, 3.0f), Vec3(3.0f, 2.0f, 5.0f), Vec3(0.5f)};
    b.lastAge = {20, 20, 20};
    b.ray = {Vec3(0.25f), Vec3(0.5f), Vec3(4.0f, 0.0f, 2.0f), Vec3(2.0f, 8.0f, 0.0f)};
    const Vec3 nearSum(0.75f), own(3.0f, 4.0f, 1.0f), prior(2.0f, 2.0f, 4.0f);
    SECTION("a new texel with neighbours in view") {
        psplit::sumSplitTexel(b, 0);
        for (int c = 0; c < 3; ++c) {
            const float expected = 0.25f * own[c] + 0.75f * prior[c];
            CHECK(b.far[c] == Approx(expected).epsilon(1e-6));
            CHECK(b.Lr[c] == Approx(nearSum[c] + expected).epsilon(1e-6));
        }
        CHECK(b.age == 8);
    }
    SECTION("a texel with a history of its own: the prior is not read") {
        psplit::sumSplitTexel(b, 1);
        for (int c = 0; c < 3; ++c) CHECK(b.far[c] == Approx(0.1f * own[c] + 0.9f * 0.5f).epsilon(1e-6));
        CHECK(b.age == 22);
    }
    SECTION("a new texel whose near lights were not in view: its own rays alone") {
        psplit::sumSplitTexel(b, 2);
        CHECK(b.far == own);
        CHECK(b.age == 2);
    }
    SECTION("far_share: every texel shows its far mean blended with its neighbours', its history keeping its own") {
        // Texel 1 (in view last frame, age 20 + 2 far rays): its own far
        // mean f = 0.1 own + 0.9 x 0.5, weighed by its age 22 (less than
        // S (1 + h) / (1 - h) = 38) against far_share 11: Lr shows 2/3 f +
        // 1/3 of its one near light's far mean b; the history keeps f.
        b.p.farShare = 11;
        psplit::sumSplitTexel(b, 1);
        for (int c = 0; c < 3; ++c) {
            const float f = 0.1f * own[c] + 0.9f * 0.5f;
            CHECK(b.far[c] == Approx(f).epsilon(1e-6));
            CHECK(b.Lr[c] == Approx(nearSum[c] + (2.0f * f + b.lastFar[1][c]) / 3.0f).epsilon(1e-6));
        }
        // Without the running mean's age its own far mean stands for the
        // exponential average's 38 rays: 38 / 49 of it.
        b.p.historyMean = false;
        psplit::sumSplitTexel(b, 1);
        for (int c = 0; c < 3; ++c) {
            const float f = 0.1f * own[c] + 0.9f * 0.5f;
            CHECK(b.Lr[c] == Approx(nearSum[c] + (38.0f * f + 11.0f * b.lastFar[1][c]) / 49.0f).epsilon(1e-5));
        }
        // A texel none of whose near lights was in view shows its own.
        b.p.historyMean = true;
        psplit::sumSplitTexel(b, 2);
        CHECK(b.Lr == nearSum + own);
    }
    SECTION("history_start first: the same blend, no age") {
        b.p.historyMean = false;
        b.age = 99;
        psplit::sumSplitTexel(b, 0);
        for (int c = 0; c < 3; ++c) CHECK(b.far[c] == Approx(0.25f * own[c] + 0.75f * prior[c]).epsilon(1e-6));
        CHECK(b.age == 99);
    }
}

namespace {

/// A static disk and camera with the far history's running mean, 4 frames
/// rendered with and without `option`: the same frames, bit for bit.
void requireStaticDiskUnchanged(void (*option)(Settings&)) {
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
    s.shading.visibility = true;
    s.particles.gm = 0.0;
    s.render.frames = 4;
    s.particle_split.history = 0.9;
    s.particle_split.history_of = HistoryOf::far;
    s.particle_split.history_start = HistoryStart::mean;
    const ParticleSource source(s);
    Settings with = s;
    option(with);
    FrameRenderer a(s, source, RenderOptions{true}), b(with, source, RenderOptions{true});
    for (std::uint32_t f = 0; f < 4; ++f) {
        FrameStats sa, sb;
        const FrameImage x = a.render(f, sa), y = b.render(f, sb);
        REQUIRE(x.lighting.Lr == y.lighting.Lr);
    }
}

}  // namespace

TEST_CASE("particle_split: far_prior changes nothing where no particle comes into view", "[particle_split]") {
    // Frame 0 has no history (no neighbour's far mean to start from), and
    // later frames no new texel.
    requireStaticDiskUnchanged([](Settings& s) { s.particle_split.far_prior = 8; });
}

TEST_CASE("particle_split: far_handoff moves the lights that joined or left the near set between the far history and the near sum, in closed form",
          "[particle_split]") {
    // Near 3, far 2, h 0.9 (history_start first): texel 1 (particle 1) has
    // near lights 7, 4 and 9 now; last frame (its slot 2) it had 4, 3 and 8,
    // with near terms (4) a, (3) b and (8) c. 7 and 9 joined the near set:
    // the history's far light held them (at their far terms then); 3 and 8
    // left it: the history lacks them. Its history, as if its frames had
    // taken this frame's near set out: last far - (v7 + v9) + (b + c).
    PriorBridge b;
    b.p.nearCount = 3;
    b.p.farSamples = 2;
    b.p.history = 0.9f;
    b.p.historyOfFar = true;
    b.p.farHandoff = true;
    b.near = {{5}, {7, 4, 9}};
    b.lastSlot.assign(8, kNoSlot);
    b.lastSlot[1] = 2;
    b.lastFar = {Vec3(0.0f), Vec3(0.0f), Vec3(6.0f, 5.0f, 4.0f)};
    b.lastNear = {{}, {}, {4, 3, 8}};
    const Vec3 a(0.5f, 0.25f, 1.0f), bb(1.0f, 2.0f, 0.5f), c(0.25f, 0.5f, 0.75f);
    b.lastNearValue = {{}, {}, {a, bb, c}};
    const Vec3 v7(1.0f, 0.5f, 0.25f), v4(0.75f), v9(0.5f, 1.5f, 1.0f);
    b.ray = {v7, v4, v9, Vec3(4.0f, 0.0f, 2.0f), Vec3(2.0f, 8.0f, 0.0f)};
    const Vec3 own(3.0f, 4.0f, 1.0f);
    SECTION("a texel with history") {
        psplit::sumSplitTexel(b, 1);
        const Vec3 last = b.lastFar[2] - (v7 + v9) + (bb + c);
        for (int k = 0; k < 3; ++k) {
            CHECK(b.far[k] == Approx(0.1f * own[k] + 0.9f * last[k]).epsilon(1e-6));
            CHECK(b.Lr[k] == Approx(v7[k] + v4[k] + v9[k] + 0.1f * own[k] + 0.9f * last[k]).epsilon(1e-6));
        }
        // This frame's near terms, in the order of its near lights, for the next frame.
        REQUIRE(b.nearWritten.size() == 3);
        CHECK(b.nearWritten[0] == v7);
        CHECK(b.nearWritten[1] == v4);
        CHECK(b.nearWritten[2] == v9);
    }
    SECTION("the same near set: the history as it is") {
        b.lastNear[2] = {9, 7, 4};
        psplit::sumSplitTexel(b, 1);
        for (int k = 0; k < 3; ++k) CHECK(b.far[k] == Approx(0.1f * own[k] + 0.9f * b.lastFar[2][k]).epsilon(1e-6));
    }
    SECTION("without far_handoff the history is read as it is, no near term kept") {
        b.p.farHandoff = false;
        psplit::sumSplitTexel(b, 1);
        for (int k = 0; k < 3; ++k) CHECK(b.far[k] == Approx(0.1f * own[k] + 0.9f * b.lastFar[2][k]).epsilon(1e-6));
        CHECK(b.nearWritten.empty());
    }
    SECTION("a texel new to the view keeps its near terms and reads no history") {
        b.near[0] = {5, 6, 7};
        psplit::sumSplitTexel(b, 0);
        CHECK(b.far == own);
        REQUIRE(b.nearWritten.size() == 3);
        CHECK(b.nearWritten[2] == v9);
    }
}

TEST_CASE("particle_split: far_handoff changes nothing where no near set changes", "[particle_split]") {
    // Every particle keeps its near set.
    requireStaticDiskUnchanged([](Settings& s) { s.particle_split.far_handoff = true; });
}

TEST_CASE("particle_split: the steady state is the frames after which the first weighs under 1%, in closed form", "[particle_split]") {
    Settings s = splitSettings(ShadingModel::lambert, 400, 4, 2);
    s.render.estimator = EstimatorKind::particle_split;
    s.particle_split.history = 0.95;
    // From the first frame: it weighs 0.95^n, 0.95^90 < 0.01 <= 0.95^89.
    CHECK(steadyStateHistory(s) == 90);
    // A running mean: after n frames the first weighs 1/(n+1) until that
    // falls to 1 - h = 1/20 (n = 19), then 0.95 less each frame:
    // 0.05 x 0.95^32 < 0.01 <= 0.05 x 0.95^31, so 19 + 32. The same for any
    // number of far rays a frame, and far_prior adds nothing to frame 0.
    s.particle_split.history_start = HistoryStart::mean;
    for (const std::uint32_t far : {1u, 4u, 8u}) {
        s.particle_split.far = far;
        CHECK(steadyStateHistory(s) == 51);
    }
    s.particle_split.far_prior = 32;
    CHECK(steadyStateHistory(s) == 51);
    // far_new 16 of far 4: the first frame weighs 16 of the 16 + 4n rays
    // until 4 / (16 + 4n) falls to 1/20 (n = 16, 16/80), then 0.95^m:
    // 0.2 x 0.95^59 < 0.01 <= 0.2 x 0.95^58, so 16 + 59.
    s.particle_split.far = 4;
    s.particle_split.far_new = 16;
    CHECK(steadyStateHistory(s) == 75);
    // Never under 8 frames, none without a history.
    s.particle_split.far_new = 0;
    s.particle_split.history = 0.5;
    CHECK(steadyStateHistory(s) == 8);
    s.particle_split.history = 0.0;
    CHECK(steadyStateHistory(s) == 0);
}
