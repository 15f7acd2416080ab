// restir's options do what they say: the M cap, reduced-resolution lighting,
// packed layouts and partial BVH rebuilds.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "accretion/render/frame_renderer.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

Settings staticScene() {
    Settings s = accretion::test::smallDiskSettings();
    s.particles.gm = 0.0;  // static particles, static camera: every pixel reprojects onto itself
    s.render.estimator = EstimatorKind::restir;
    s.render.candidates = 4;
    return s;
}

std::vector<FrameImage> renderFrames(Settings s, std::uint32_t frames, std::vector<FrameStats>* stats = nullptr) {
    s.render.frames = frames;  // the pass plan keeps restir's history for more than one frame
    FrameRenderer renderer(s, ParticleSource(s), RenderOptions{true});
    std::vector<FrameImage> out;
    for (std::uint32_t f = 0; f < frames; ++f) {
        FrameStats fs;
        out.push_back(renderer.render(f, fs));
        if (stats) stats->push_back(fs);
    }
    return out;
}

}  // namespace

TEST_CASE("temporal reuse caps the history at m_cap x M", "[restir]") {
    Settings s = staticScene();
    s.restir.spatial_neighbours = 0;
    s.restir.m_cap = GENERATE(0.0, 3.0, 20.0);
    const std::uint32_t n = 24;
    const auto frames = renderFrames(s, n);
    // M_t = M_c + min(M_{t-1}, C M_c): M_c (t + 1) until it reaches M_c (1 + C).
    const float expected0 = float(s.render.candidates);
    const float expected = float(s.render.candidates) * float(std::min<double>(n, 1.0 + s.restir.m_cap));
    std::size_t hits = 0;
    for (std::size_t px = 0; px < frames[0].particle.size(); ++px) {
        if (frames[0].particle[px] == kNoParticle) continue;
        ++hits;
        REQUIRE(frames[0].reservoirs.M[px] == expected0);
        REQUIRE(frames[n - 1].reservoirs.M[px] == expected);
    }
    REQUIRE(hits > 200);
}

TEST_CASE("reduced-resolution lighting resamples a quarter of the pixels and upsamples to all", "[restir]") {
    Settings s = staticScene();
    s.restir.temporal = false;
    s.restir.spatial_neighbours = 0;
    std::vector<FrameStats> full, half;
    const auto a = renderFrames(s, 1, &full);
    Settings h = s;
    h.restir.resolution_scale = 0.5;
    const auto b = renderFrames(h, 1, &half);
    // Candidate evaluations are candidates x lit texels of the lighting grid.
    const double ratio = double(half[0].lighting.lightTerms) / double(full[0].lighting.lightTerms);
    INFO("light-term ratio " << ratio);
    CHECK(ratio > 0.15);
    CHECK(ratio < 0.35);
    // Every hit pixel of the full image gets lighting from a similar low-res texel.
    std::size_t lit = 0, hits = 0;
    for (std::size_t px = 0; px < b[0].particle.size(); ++px) {
        if (b[0].particle[px] == kNoParticle) {
            REQUIRE(b[0].lighting.Lr[px] == Vec3(0.0f));
            continue;
        }
        ++hits;
        lit += luminance(b[0].lighting.Lr[px]) > 0.0f;
    }
    CHECK(lit > hits / 4);
    // Same light on average: image sums over 16 seeds (one sample per texel
    // each; about 6% standard error at half resolution) agree within 20%.
    double sumA = 0.0, sumB = 0.0;
    for (std::uint64_t seed = 0; seed < 16; ++seed) {
        s.render.seed = h.render.seed = seed;
        const auto fa = renderFrames(s, 1), fb = renderFrames(h, 1);  // (a range-for over a member of a temporary dangles)
        for (const Vec3& v : fa[0].lighting.Lr) sumA += luminance(v);
        for (const Vec3& v : fb[0].lighting.Lr) sumB += luminance(v);
    }
    CHECK(sumB == Approx(sumA).epsilon(0.2));
}

TEST_CASE("a packed 8-byte layout that addresses every light changes only rounding", "[restir][codec]") {
    Settings s = staticScene();
    const auto full = renderFrames(s, 3);
    s.restir.layout = ReservoirLayout::packed;
    s.restir.light_bits = 12;
    std::vector<FrameStats> stats;
    const auto packed = renderFrames(s, 3, &stats);
    REQUIRE(stats[0].reservoirBytes == 8);
    // Same streams, same choices up to half-precision W and p_hat: the image
    // sum agrees to well within a percent.
    double a = 0.0, b = 0.0;
    for (std::size_t px = 0; px < full[2].lighting.Lr.size(); ++px) {
        a += luminance(full[2].lighting.Lr[px]);
        b += luminance(packed[2].lighting.Lr[px]);
    }
    CHECK(b == Approx(a).epsilon(0.02));
    CHECK(b != a);  // half precision did change something
}

TEST_CASE("partial BVH rebuild: a round-robin fraction of clusters, identical image for static particles", "[geometry][restir]") {
    Settings s = accretion::test::smallDiskSettings();
    s.particles.count = 600;
    s.particles.gm = 0.0;
    s.geometry.cluster_size = 20;
    // The BVH itself (a frame renderer would build a static scene once): the
    // same particles built three times, fully and partially.
    const Particles p = ParticleSource(s).frame(0);
    const Camera cam = Camera::atFrame(s.camera, 0);
    EmbreeDevice device;
    ParticleBvh full(device, s.geometry);
    s.geometry.build = BuildPolicy::partial;
    s.geometry.rebuild_fraction = 0.3;
    ParticleBvh partial(device, s.geometry);
    std::vector<BvhStats> stats;
    GBuffer a, b;
    for (int f = 0; f < 3; ++f) {
        full.build(p, cam);
        partial.build(p, cam);
        stats.push_back(partial.stats());
    }
    const std::size_t C = stats[0].clusters;
    REQUIRE(C > 10);
    CHECK(stats[0].rebuiltClusters == C);  // the first build builds everything
    CHECK(stats[1].rebuiltClusters == std::size_t(std::ceil(0.3 * double(C))));
    CHECK(stats[1].partial);
    // Static particles: stale clusters are exact, so every primary hit is unchanged.
    traceGBuffer(full, p, cam, s.shading.model, a);
    traceGBuffer(partial, p, cam, s.shading.model, b);
    std::size_t hits = 0;
    for (std::size_t px = 0; px < a.texels.size(); ++px) {
        REQUIRE(a.texels[px].particle == b.texels[px].particle);
        REQUIRE(a.texels[px].local == b.texels[px].local);
        hits += a.texels[px].hit();
    }
    CHECK(hits > 100);
}
