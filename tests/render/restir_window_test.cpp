// restir on render.crop with restir.crop_margin renders a window of the
// frame as an image of its own (Camera::window), its texels' streams keyed
// by their place in the whole frame. Where every pixel a crop pixel's reuse
// reads (its spatial neighbours, its history, theirs, over the frames) lies
// within the margin, the crop is the whole frame's bit for bit; without the
// margin the crop's edge loses the neighbours beyond it.
#include <catch2/catch.hpp>

#include "accretion/render/frame_renderer.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

/// The last of `frames` frames of a moving disk.
FrameImage lastFrame(const Settings& s, std::uint32_t frames) {
    FrameRenderer renderer(s, ParticleSource(s), RenderOptions{true});
    FrameImage img;
    for (std::uint32_t f = 0; f < frames; ++f) {
        FrameStats stats;
        img = renderer.render(f, stats);
    }
    return img;
}

/// Pixels of the crop whose Lr differs from the whole frame's.
std::size_t differing(const FrameImage& whole, const FrameImage& crop, std::uint32_t width) {
    const PixelWindow& w = crop.window;
    std::size_t n = 0;
    for (std::uint32_t y = w.y0; y < w.y1; ++y)
        for (std::uint32_t x = w.x0; x < w.x1; ++x)
            n += whole.lighting.Lr[std::size_t(y) * width + x] != crop.lighting.Lr[w.index(x, y)];
    return n;
}

}  // namespace

TEST_CASE("restir on a crop and its margin renders the crop as the whole frame does", "[render][restir][window]") {
    struct Case {
        const char* name;
        LightSource source;
        double scale;
    };
    const Case c = GENERATE(Case{"uniform candidates", LightSource::uniform, 1.0}, Case{"light tiles", LightSource::tiles, 1.0},
                            Case{"lighting at 0.5x", LightSource::power, 0.5});
    INFO(c.name);
    Settings s = test::smallDiskSettings();
    s.camera.width = 96;
    s.camera.height = 64;
    s.render.estimator = EstimatorKind::restir;
    s.render.source = c.source;
    s.render.candidates = 4;
    s.render.frames = 3;
    s.render.seed = 11;
    s.restir.spatial_neighbours = 3;
    s.restir.spatial_radius = 2.0;
    s.restir.resolution_scale = c.scale;
    s.restir.tile_count = 4;
    s.restir.tile_size = 32;
    const FrameImage whole = lastFrame(s, 3);

    const PixelWindow crop{40, 56, 24, 40};  // on the 8-pixel grid: margin 0 renders it alone
    s.render.crop = {double(crop.x0), double(crop.x1), double(crop.y0), double(crop.y1)};
    s.restir.crop_margin = 16;  // three frames of one spatial pass of radius 2, and the disk's motion
    const FrameImage withMargin = lastFrame(s, 3);
    REQUIRE(withMargin.window == crop);
    REQUIRE(withMargin.width == s.camera.width);
    REQUIRE(withMargin.lighting.Lr.size() == crop.pixels());
    std::size_t lit = 0;
    for (const Vec3& v : withMargin.lighting.Lr) lit += v.x > 0.0f;
    CHECK(lit > 40);  // the crop shows the disk, lit
    CHECK(differing(whole, withMargin, s.camera.width) == 0);
    for (std::size_t k = 0; k < withMargin.particle.size(); ++k) {
        const std::uint32_t x = crop.x0 + std::uint32_t(k % crop.width()), y = crop.y0 + std::uint32_t(k / crop.width());
        REQUIRE(withMargin.particle[k] == whole.particle[std::size_t(y) * s.camera.width + x]);
        REQUIRE(withMargin.depth[k] == whole.depth[std::size_t(y) * s.camera.width + x]);
    }

    s.restir.crop_margin = 0;  // the crop alone: its edge's neighbours and history beyond it are off-screen
    CHECK(differing(whole, lastFrame(s, 3), s.camera.width) > 0);
}

TEST_CASE("Lanes on one frame's geometry give each lane the image of its own renderer", "[render][restir][window][lanes]") {
    // Two seeds by two crops (and the whole frame) of restir with temporal
    // and spatial reuse over 4 frames, and ris: each lane bit for bit what a
    // renderer of its settings alone gives, its history its own.
    const EstimatorKind kind = GENERATE(EstimatorKind::restir, EstimatorKind::ris);
    INFO(enumName(kind));
    Settings s = test::smallDiskSettings();
    s.camera.width = 96;
    s.camera.height = 64;
    s.render.estimator = kind;
    s.render.source = LightSource::tree;
    s.render.candidates = 4;
    s.render.samples = 2;
    s.render.frames = 4;
    s.restir.spatial_neighbours = 3;
    s.restir.spatial_radius = 4.0;
    std::vector<Settings> lanes;
    for (std::uint64_t seed : {5u, 9u}) {
        Settings l = s;
        l.render.seed = seed;
        lanes.push_back(l);  // the whole frame
        for (const PixelWindow& w : {PixelWindow{8, 40, 8, 32}, PixelWindow{50, 90, 30, 60}}) {
            l.render.crop = {double(w.x0), double(w.x1), double(w.y0), double(w.y1)};
            l.restir.crop_margin = kind == EstimatorKind::restir ? 8.0 : -1.0;
            lanes.push_back(l);
        }
    }
    FrameRenderer renderer(lanes, ParticleSource(s), RenderOptions{true});
    std::vector<FrameImage> images;
    for (std::uint32_t f = 0; f < 4; ++f) {
        FrameStats shared;
        std::vector<FrameStats> stats;
        images = renderer.renderLanes(f, shared, stats);
        REQUIRE(stats.size() == lanes.size());
        CHECK(shared.particles > 0);
    }
    REQUIRE(images.size() == lanes.size());
    std::size_t lit = 0;
    for (std::size_t k = 0; k < lanes.size(); ++k) {
        INFO("lane " << k);
        const FrameImage alone = lastFrame(lanes[k], 4);
        REQUIRE(images[k].window == alone.window);
        CHECK(images[k].lighting.Lr == alone.lighting.Lr);
        CHECK(images[k].particle == alone.particle);
        for (const Vec3& v : alone.lighting.Lr) lit += v.x > 0.0f;
    }
    CHECK(lit > 100);
    CHECK(images[0].lighting.Lr != images[3].lighting.Lr);  // the seeds differ

    // Lanes share everything but their seed and crop.
    Settings other = lanes[1];
    other.render.candidates = 8;
    CHECK_THROWS_AS(FrameRenderer(std::vector<Settings>{lanes[0], other}, ParticleSource(s)), std::invalid_argument);
}
