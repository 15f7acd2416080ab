// particle_restir (docs/MODEL.md section 4b): the texel geometry in closed
// form, the gather's slots, and the resampled pixels against the
// brute-force oracle (tests/support/oracle.h, no code shared with the
// renderer) over independent seeds, as restir_test.cpp checks restir: the
// statistic is the image sum of Lr per seed (one history per seed).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "accretion/geometry/billboard.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/render/particle_texel_grid.h"
#include "support/seed_sums.h"
#include "support/statistics.h"
#include "support/test_scenes.h"

using namespace accretion;

TEST_CASE("bilinearTexels: weights sum to 1, reproduce a linear function inside, clamp at the edges", "[particle_restir]") {
    for (const std::uint32_t side : {1u, 2u, 4u}) {
        // A linear function of the texel centre, f(u, v) = 3u - 2v + 1.
        const auto f = [](Vec2 uv) { return 3.0f * uv.x - 2.0f * uv.y + 1.0f; };
        for (float u = 0.0f; u <= 1.0f; u += 0.0625f)
            for (float v = 0.0f; v <= 1.0f; v += 0.0625f) {
                std::uint32_t sub[4];
                float w[4];
                const std::uint32_t n = bilinearTexels(Vec2(u, v), side, sub, w);
                float sum = 0.0f, value = 0.0f;
                for (std::uint32_t k = 0; k < n; ++k) {
                    REQUIRE(sub[k] < side * side);
                    REQUIRE(w[k] >= 0.0f);
                    sum += w[k];
                    value += w[k] * f(texelUv(sub[k], side));
                }
                INFO("side " << side << " uv " << u << "," << v);
                CHECK(sum == Approx(1.0f).margin(1e-6));
                // Between the outer texel centres the interpolation of a linear
                // function is exact; outside them it is the edge's (clamped).
                const float lo = 0.5f / float(side), hi = 1.0f - lo;
                if (side == 1) CHECK(value == Approx(f(Vec2(0.5f))).margin(1e-5));
                else CHECK(value == Approx(f(glm::clamp(Vec2(u, v), Vec2(lo), Vec2(hi)))).margin(1e-5));
            }
    }
}

TEST_CASE("billboardPointTexel: the point at uv on the quad, its normal towards the camera, billboardUv inverts it", "[particle_restir]") {
    const Camera camera = Camera::lookAt(Vec3(0.3f, 2.0f, 9.0f), Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 40.0, 64, 48);
    const Vec3 p(0.5f, -0.25f, 1.0f);
    const float r = 0.2f;
    for (const Orientation mode : {Orientation::view_plane, Orientation::view_point}) {
        const BillboardFrame f = billboardFrame(mode, camera, p, Vec3(0.0f));
        for (const std::uint32_t side : {1u, 2u, 4u})
            for (std::uint32_t s = 0; s < side * side; ++s) {
                const Vec2 uv = texelUv(s, side);
                const GBufferTexel g = billboardPointTexel(camera, 7, p, r, f, uv, ShadingModel::lambert);
                INFO(enumName(mode) << " side " << side << " texel " << s);
                CHECK(g.particle == 7u);
                // p + (2u - 1) r right + (2v - 1) r up, in closed form.
                const Vec3 expect = (2.0f * uv.x - 1.0f) * r * f.right + (2.0f * uv.y - 1.0f) * r * f.up;
                CHECK(glm::length(g.local - expect) < 1e-6f);
                CHECK(std::fabs(glm::dot(g.normal, glm::normalize(f.normal()))) == Approx(1.0f).margin(1e-6));
                CHECK(glm::dot(g.normal, camera.position - (p + g.local)) > 0.0f);
                const Vec2 back = billboardUv(g.local, r, f);
                CHECK(back.x == Approx(uv.x).margin(1e-5));
                CHECK(back.y == Approx(uv.y).margin(1e-5));
                CHECK(g.depth == Approx(glm::dot(p + g.local - camera.position, camera.forward)).margin(1e-5));
            }
    }
}

TEST_CASE("mortonKey orders the cube by its octants, then within them", "[particle_restir]") {
    // The first split is z, then y, then x (x the lowest bit of each triple).
    CHECK(mortonKey(Vec3(0.1f, 0.1f, 0.1f)) < mortonKey(Vec3(0.9f, 0.1f, 0.1f)));
    CHECK(mortonKey(Vec3(0.9f, 0.1f, 0.1f)) < mortonKey(Vec3(0.1f, 0.9f, 0.1f)));
    CHECK(mortonKey(Vec3(0.9f, 0.9f, 0.1f)) < mortonKey(Vec3(0.1f, 0.1f, 0.9f)));
    CHECK(mortonKey(Vec3(0.0f)) == 0u);
    CHECK(mortonKey(Vec3(1.0f)) == (std::uint64_t(1) << 63) - 1);  // 21 bits an axis, all set
    CHECK(mortonKey(Vec3(-1.0f)) == 0u);  // clamped
}

TEST_CASE("particle_restir: every particle a pixel sees has one slot and its texels, in Morton order", "[particle_restir]") {
    Settings s = test::smallDiskSettings();
    s.particles.count = 300;
    s.camera.width = 96;
    s.camera.height = 64;
    s.restir.texels = 2;
    s.restir.texel_rays = 3;
    const test::TracedFrame f(s);
    const Particles& particles = f.particles;
    const ParticleBvh& bvh = f.bvh;
    const GBuffer& gbuffer = f.gbuffer;
    const ParticleTexels t = gatherParticleTexels(gbuffer, particles, bvh, f.camera, s.shading.model, s.restir.texels, s.restir.texel_rays,
                                                  TexelPointRule{});

    std::vector<std::uint8_t> seen(particles.size(), 0);
    for (const GBufferTexel& g : gbuffer.texels)
        if (g.hit()) seen[g.particle] = 1;
    REQUIRE(t.visible() == std::size_t(std::count(seen.begin(), seen.end(), 1)));
    REQUIRE(t.visible() > 20);
    const MortonFrame m = mortonFrame(particles.position.data(), particles.size());
    for (std::uint32_t j = 0; j < particles.size(); ++j) {
        INFO("particle " << j);
        REQUIRE((t.slotOf[j] != kNoSlot) == bool(seen[j]));
        if (seen[j]) REQUIRE(t.particleOf[t.slotOf[j]] == j);
    }
    for (std::uint32_t v = 1; v < t.visible(); ++v) {
        const std::uint64_t a = m.key(particles.position[t.particleOf[v - 1]]), b = m.key(particles.position[t.particleOf[v]]);
        REQUIRE((a < b || (a == b && t.particleOf[v - 1] < t.particleOf[v])));
    }
    // 2x2 texels x 3 layers a particle, 8 a row, the tail missing.
    REQUIRE(t.grid.width == kTexelRowWidth);
    REQUIRE(t.grid.texels.size() == (t.texels() + 7) / 8 * 8);
    for (std::size_t q = 0; q < t.grid.texels.size(); ++q) {
        const GBufferTexel& g = t.grid.texels[q];
        if (q >= t.texels()) {
            REQUIRE_FALSE(g.hit());
            continue;
        }
        const std::uint32_t j = t.particleOf[q / t.perParticle()], sub = std::uint32_t(q % t.perParticle()) % 4;
        REQUIRE(g.particle == j);
        const Vec2 uv = billboardUv(g.local, particles.radius[j], bvh.frame(j));
        REQUIRE(uv.x == Approx(texelUv(sub, 2).x).margin(1e-4));
        REQUIRE(uv.y == Approx(texelUv(sub, 2).y).margin(1e-4));
    }
}

TEST_CASE("particle_restir resampled at the pixels agrees with the oracle", "[particle_restir][statistical][long]") {
    // pixel_shading resample: each pixel resamples its particle's texels at
    // its own point with basic weights and traces its own shadow ray; the
    // texels' chains (temporal by id, 3 world neighbours) are unbiased with
    // basic or pairwise. An animated disk and an orbiting camera, 4 frames;
    // |z| < 4.4 over the seeds (p ~ 1e-5 for an unbiased estimator).
    // none (1/M) in the texels' chains is biased, and caught: the harness has power.
    const BiasCorrection correction = GENERATE(BiasCorrection::basic, BiasCorrection::pairwise, BiasCorrection::none);
    const bool biased = correction == BiasCorrection::none;
    INFO(enumName(correction));
    Settings s = test::smallDiskSettings();
    s.particles.count = 300;
    s.camera.width = 96;
    s.camera.height = 64;
    s.camera.path = CameraPath::orbit;
    s.camera.orbit_speed = 2.0;
    s.particles.time_step = 0.01;
    s.render.candidates = 4;
    s.restir.bias_correction = correction;
    s.restir.pixel_shading = PixelShading::resample;
    s.restir.texels = 2;
    s.restir.texel_rays = 2;
    s.restir.spatial_neighbours = 3;
    s.restir.world_neighbours = 4;
    const std::uint32_t frames = 4, seeds = test::statisticalSeeds(biased ? 50 : 200);
    static const double oracle = test::oracleImageSum(s, frames - 1);  // the same scene for the three corrections
    const auto [mean, stderr] = test::seedImageSums(s, EstimatorKind::particle_restir, frames, seeds, 2000);
    const double z = (mean - oracle) / stderr;
    INFO("oracle " << oracle << ", particle_restir " << mean << " +- " << stderr << ", z " << z);
    if (biased) {
        CHECK(std::fabs(z) > 4.4);
        return;
    }
    CHECK(std::fabs(z) < 4.4);
    // The harness would see a 5% bias (4.4 + 1 standard errors below 5% of the sum).
    if (test::fullStatisticalPower()) CHECK(5.4 * stderr < 0.05 * oracle);
}
