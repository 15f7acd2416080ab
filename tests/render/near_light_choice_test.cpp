// split's automatic k (render.near_lights = 0): a pilot on a low-resolution
// image of the frame's view measures the far field's variance at each
// candidate k and picks the least error x time for the samples asked
// (docs/MODEL.md section 4).
#include <catch2/catch.hpp>

#include <bit>
#include <cstring>
#include <limits>

#include "accretion/scene/scene_parser.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

NearLightChoice pilotOf(const Settings& s, const Particles& particles) {
    FrameRenderer renderer(s, ParticleSource::fixed(particles), RenderOptions{true});
    FrameStats stats;
    renderer.render(0, stats);
    return stats.nearLights;
}

/// The candidate of least relVariance x cost (ties: the smaller k).
std::uint32_t argmin(const NearLightChoice& c) {
    std::uint32_t k = 0;
    double best = std::numeric_limits<double>::infinity();
    for (const NearLightChoice::Candidate& x : c.candidates)
        if (x.relVariance * x.cost < best) best = x.relVariance * x.cost, k = x.k;
    return k;
}

}  // namespace

TEST_CASE("split's automatic k: one pilot per view, k grows with the samples asked, the same for a crop", "[estimators][split]") {
    Settings s = loadScene(std::string(ACCRETION_SOURCE_DIR) + "/scenes/quickstart.toml",
                           {"camera.width=160", "camera.height=90", "render.estimator=\"split\"", "render.near_lights=0"});
    const Particles particles = ParticleSource(s).frame(0);
    REQUIRE(particles.size() > NearField::kMaxNear);
    // One pixel of each render: the pilot does not depend on the window (checked below).
    s.render.crop = {40, 41, 50, 51};
    std::vector<NearLightChoice> choices;
    for (std::uint32_t samples : {1u, 16u, 256u, 4096u}) {
        s.render.samples = samples;
        choices.push_back(pilotOf(s, particles));
    }
    const NearLightChoice& first = choices.front();
    REQUIRE(first.pixels == 256);  // the pilot's 64x36 image holds more lit pixels: 256 evenly spaced
    // The candidates: 16, 32, ..., kMaxNear near lights.
    REQUIRE(first.candidates.size() == std::size_t(std::countr_zero(NearField::kMaxNear / 16u)) + 1);
    for (std::size_t c = 0; c < first.candidates.size(); ++c) CHECK(first.candidates[c].k == (16u << c));
    CHECK(first.candidates.back().k == NearField::kMaxNear);
    for (std::size_t i = 0; i < choices.size(); ++i) {
        INFO("samples choice " << i << ": k = " << choices[i].k);
        CHECK(choices[i].k == argmin(choices[i]));
        // V(k) is the view's alone: the same numbers whatever S.
        for (std::size_t c = 0; c < first.candidates.size(); ++c)
            CHECK(choices[i].candidates[c].relVariance == first.candidates[c].relVariance);
        // More samples make the far field dearer: k never falls as S grows.
        if (i > 0) CHECK(choices[i].k >= choices[i - 1].k);
    }
    // A larger near field leaves less to sample: V falls from the smallest k to the largest.
    CHECK(first.candidates.back().relVariance < first.candidates.front().relVariance);

    // The whole image, or a crop of the same view at another resolution: the same pilot, bit for bit.
    Settings whole = s;
    whole.render.crop.clear();
    whole.render.samples = 1;
    Settings larger = s;
    larger.camera.width = 320;
    larger.camera.height = 180;
    larger.render.crop = {200, 201, 100, 101};
    larger.render.samples = 1;
    for (const Settings* other : {&whole, &larger}) {
        const NearLightChoice c = pilotOf(*other, particles);
        CHECK(c.k == first.k);
        REQUIRE(c.candidates.size() == first.candidates.size());
        for (std::size_t k = 0; k < c.candidates.size(); ++k)
            CHECK(std::memcmp(&c.candidates[k].relVariance, &first.candidates[k].relVariance, sizeof(double)) == 0);
    }
}

TEST_CASE("split's automatic k takes every other light when the near field can hold them: the render is exact", "[estimators][split]") {
    Settings s = accretion::test::smallDiskSettings();  // 150 particles
    s.render.estimator = EstimatorKind::split;
    s.render.near_lights = 0;
    s.render.samples = 2;
    const Particles particles = ParticleSource(s).frame(0);
    const NearLightChoice c = pilotOf(s, particles);
    // 16, 32, 64, 128, then all 149: no far light is left, so its variance is 0.
    REQUIRE(c.candidates.size() == 5);
    CHECK(c.candidates.back().k == particles.size() - 1);
    CHECK(c.candidates.back().relVariance == 0.0);
    CHECK(c.candidates.front().relVariance > 0.0);
    CHECK(c.k == particles.size() - 1);
    // And the image is exact's (the same terms, summed in tree order).
    const FrameImage exact = accretion::test::renderParticles([&] { Settings e = s; e.render.estimator = EstimatorKind::exact; return e; }(), particles);
    const FrameImage split = accretion::test::renderParticles(s, particles);
    for (std::size_t px = 0; px < exact.lighting.Lr.size(); ++px)
        for (int ch = 0; ch < 3; ++ch) {
            CHECK(split.lighting.Lr[px][ch] == Approx(exact.lighting.Lr[px][ch]).epsilon(1e-5).margin(1e-12));
            CHECK(split.lighting.Lr_stderr[px][ch] == 0.0f);
        }
}
