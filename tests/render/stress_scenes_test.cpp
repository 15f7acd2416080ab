// The stress scenes (scenes/stress/): extreme scales, positions, emissions
// and degenerate configurations. Every estimator must give finite output;
// the unbiased ones must still agree with `exact`; a receiver far from the
// origin must not shadow itself (closed form).
#include <catch2/catch.hpp>

#include <map>

#include <cmath>
#include <string>

#include "accretion/particles/particle_source.h"
#include "accretion/scene/scene_parser.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

Settings stressScene(const std::string& name) {
    return loadScene(std::string(ACCRETION_SOURCE_DIR) + "/scenes/stress/" + name + ".toml");
}

bool finite(const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Every value of every layer finite (depth is +inf on a miss by definition).
void requireFinite(const FrameImage& img) {
    std::size_t bad = 0;
    for (std::size_t px = 0; px < img.L.size(); ++px) {
        bad += !finite(img.L[px]) || !finite(img.Le[px]) || !finite(img.lighting.Lr[px]) ||
               !finite(img.lighting.Lr_stderr[px]) || !finite(img.normal[px]) || !std::isfinite(img.lighting.spp[px]) ||
               !std::isfinite(img.lighting.rejected[px]) ||
               (img.particle[px] != kNoParticle && !std::isfinite(img.depth[px]));
    }
    REQUIRE(bad == 0);
}

/// Per channel, the image sum of Lr and its variance from the per-pixel
/// standard errors (independent pixel streams).
struct ImageSum {
    DVec3 sum{0.0}, var{0.0};
};
ImageSum imageSum(const FrameImage& img) {
    ImageSum s;
    for (std::size_t px = 0; px < img.L.size(); ++px) {
        s.sum += DVec3(img.lighting.Lr[px]);
        s.var += DVec3(img.lighting.Lr_stderr[px]) * DVec3(img.lighting.Lr_stderr[px]);
    }
    return s;
}

// The global z bound of the agreement test (estimator_agreement_test.cpp):
// |z| < 4.4 (p ~ 1e-5) inflated by 1.5 for the heavy-tailed 1/d^2 terms.
constexpr double kZ = 6.6;

}  // namespace

TEST_CASE("stress scenes: every estimator gives finite output and the unbiased ones agree with exact",
          "[stress][statistical]") {
    const std::string name = GENERATE(as<std::string>{}, "one_particle", "two_particles", "two_particles_far",
                                      "coincident", "emission_range", "far_disk", "tiny_particles",
                                      "huge_particles", "camera_inside", "grazing");
    INFO(name);
    Settings s = stressScene(name);
    const Particles particles = ParticleSource(s).frame(0);
    s.render.estimator = EstimatorKind::exact;
    const FrameImage exact = test::renderParticles(s, particles);
    requireFinite(exact);
    const ImageSum ref = imageSum(exact);
    std::size_t hits = 0;
    for (const std::uint32_t id : exact.particle) hits += id != kNoParticle;
    REQUIRE(hits > 0);  // the scene shows something

    struct Estimator {
        EstimatorKind kind;
        std::uint32_t samples, candidates;
    };
    for (const Estimator est : {Estimator{EstimatorKind::uniform, 1024, 1}, Estimator{EstimatorKind::power, 1024, 1},
                                Estimator{EstimatorKind::tree, 512, 1}, Estimator{EstimatorKind::ris, 256, 8}}) {
        INFO(enumName(est.kind));
        Settings e = s;
        e.render.estimator = est.kind;
        e.render.samples = est.samples;
        e.render.candidates = est.candidates;
        e.render.seed = 3;
        const FrameImage img = test::renderParticles(e, particles);
        requireFinite(img);
        const ImageSum got = imageSum(img);
        for (int c = 0; c < 3; ++c) {
            INFO("channel " << c << ": exact " << ref.sum[c] << ", estimate " << got.sum[c] << " +- " << std::sqrt(got.var[c]));
            if (ref.sum[c] == 0.0) {
                CHECK(got.sum[c] == 0.0);
                continue;
            }
            // (+ float rounding: with one other light `tree` is exact, variance 0)
            CHECK(std::fabs(got.sum[c] - ref.sum[c]) <= kZ * std::sqrt(got.var[c]) + 1e-5 * std::fabs(ref.sum[c]));
        }
    }

    // restir (basic bias correction, one frame: candidates + spatial reuse)
    // has no per-pixel error: its image sums over 24 seeds give one.
    Settings r = s;
    r.render.estimator = EstimatorKind::restir;
    r.render.candidates = 16;
    constexpr int kSeeds = 24;
    DVec3 m1(0.0), m2(0.0);
    for (int seed = 0; seed < kSeeds; ++seed) {
        r.render.seed = std::uint64_t(seed);
        const FrameImage img = test::renderParticles(r, particles);
        requireFinite(img);
        const DVec3 sum = imageSum(img).sum;
        m1 += sum;
        m2 += sum * sum;
    }
    const DVec3 mean = m1 / double(kSeeds);
    const DVec3 se = glm::sqrt(glm::max(m2 / double(kSeeds) - mean * mean, DVec3(0.0)) / double(kSeeds - 1));
    for (int c = 0; c < 3; ++c) {
        INFO("restir channel " << c << ": exact " << ref.sum[c] << ", mean " << mean[c] << " +- " << se[c]);
        if (ref.sum[c] == 0.0) CHECK(mean[c] == 0.0);
        else CHECK(std::fabs(mean[c] - ref.sum[c]) < kZ * se[c] + 1e-6 * ref.sum[c]);
    }
}

TEST_CASE("stress: the two-particle closed form holds at the origin and 1e5 away (no self-shadowing)", "[stress][closed_form]") {
    const std::string name = GENERATE(as<std::string>{}, "two_particles", "two_particles_far");
    INFO(name);
    Settings s = stressScene(name);
    const Particles p = ParticleSource(s).frame(0);
    REQUIRE(p.size() == 2);
    const FrameImage img = test::renderParticles(s, p);
    // Isotropic: Lr = rho I / (4 pi d^2); over the receiver (radius 0.05),
    // d varies by < 0.5% around the centre-to-centre distance.
    const double d = glm::length(DVec3(p.position[1]) - DVec3(p.position[0]));
    const Vec3 expected = s.shading.albedo * kInv4Pi * p.emission[1] / float(d * d);
    std::size_t receiver = 0;
    for (std::size_t px = 0; px < img.L.size(); ++px) {
        if (img.particle[px] != 0) continue;
        ++receiver;
        for (int c = 0; c < 3; ++c) REQUIRE(img.lighting.Lr[px][c] == Approx(expected[c]).epsilon(1.5e-2));
    }
    REQUIRE(receiver >= 20);
}

TEST_CASE("stress: the disk 1e5 from the origin gives the image of the same disk at the origin", "[stress][invariance]") {
    // far_disk's particles moved back by particles.center (exact: the result
    // is representable), with the camera moved by the same amount: frame
    // coordinates relative to the camera make the two renders bit-identical.
    Settings far = stressScene("far_disk");
    const Particles p = ParticleSource(far).frame(0);
    const Vec3 c = far.particles.center;
    Settings near = far;
    near.camera.position -= c;
    near.camera.look_at -= c;
    Particles q = p;
    for (Vec3& x : q.position) x -= c;
    for (std::size_t i = 0; i < p.size(); ++i) REQUIRE(q.position[i] + c == p.position[i]);
    const FrameImage a = test::renderParticles(far, p), b = test::renderParticles(near, q);
    std::size_t hits = 0, identical = 0;
    for (std::size_t px = 0; px < a.L.size(); ++px) {
        REQUIRE(a.particle[px] == b.particle[px]);
        if (a.particle[px] == kNoParticle) continue;
        ++hits;
        identical += a.lighting.Lr[px] == b.lighting.Lr[px] && a.depth[px] == b.depth[px];
    }
    REQUIRE(hits > 200);
    CHECK(identical == hits);
}

TEST_CASE("stress: overflowing samples are rejected by render.nonfinite, counted per pixel and per pass",
          "[stress][nonfinite]") {
    const NonFinitePolicy policy = GENERATE(NonFinitePolicy::zero_sample, NonFinitePolicy::discard);
    const EstimatorKind kind = GENERATE(EstimatorKind::exact, EstimatorKind::uniform, EstimatorKind::ris,
                                        EstimatorKind::restir, EstimatorKind::particle_restir);
    INFO(enumName(policy) << ", " << enumName(kind));
    Settings s = stressScene("emission_overflow");
    s.render.nonfinite = policy;
    s.render.estimator = kind;
    s.render.samples = 64;
    const Particles particles = ParticleSource(s).frame(0);
    FrameRenderer renderer(s, ParticleSource::fixed(particles), RenderOptions{true});
    FrameStats stats;
    const FrameImage img = renderer.render(0, stats);
    requireFinite(img);

    std::uint64_t counted = 0;
    for (const auto& [pass, n] : stats.nonFinite) counted += n;
    double perPixel = 0.0, missing = 0.0;
    for (std::size_t px = 0; px < img.L.size(); ++px) {
        perPixel += img.lighting.rejected[px];
        if (kind == EstimatorKind::uniform && img.particle[px] != kNoParticle) missing += 64.0 - img.lighting.spp[px];
    }
    CHECK(counted > 0);            // the scene does overflow
    if (kind == EstimatorKind::particle_restir) {
        // A pixel counts what was rejected at it and at its particle's
        // texels (interpolating, the pixels reject nothing of their own): the
        // pixels of one particle agree, and the particles' counts sum to the stats'.
        std::map<std::uint32_t, float> ofParticle;
        for (std::size_t px = 0; px < img.L.size(); ++px) {
            if (img.particle[px] == kNoParticle) continue;
            const auto it = ofParticle.emplace(img.particle[px], img.lighting.rejected[px]).first;
            CHECK(it->second == img.lighting.rejected[px]);
        }
        double sum = 0.0;
        for (const auto& [j, n] : ofParticle) sum += n;
        CHECK(sum == double(counted));
    } else {
        CHECK(perPixel == double(counted));  // the AOV and the stats agree
    }
    CHECK(stats.lighting.nonFinite > 0);
    if (kind == EstimatorKind::uniform) {
        // zero_sample: a rejected sample still counts (as 0); discard: it is
        // not counted. (The pass's count also holds pixels whose finite
        // double mean or error overflowed float at the end: zeroed.)
        if (policy == NonFinitePolicy::zero_sample) CHECK(missing == 0.0);
        else {
            CHECK(missing > 0.0);
            CHECK(missing <= double(stats.lighting.nonFinite));
        }
    }
}
