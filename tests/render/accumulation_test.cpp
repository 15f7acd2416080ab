// Chunked accumulation (render/accumulation.h): a frame rendered in chunk
// sweeps with a stop and a restart from the saved sums, or in shards merged
// afterwards, is bit-identical to the frame rendered in one sweep; the
// accumulation file round-trips and detects corruption.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "accretion/core/error.h"
#include "accretion/core/stop_signal.h"
#include "accretion/io/accumulation_file.h"
#include "accretion/particles/particle_source.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

void requireSameLighting(const LightingImage& a, const LightingImage& b) {
    REQUIRE(a.Lr.size() == b.Lr.size());
    std::size_t differ = 0;
    for (std::size_t px = 0; px < a.Lr.size(); ++px)
        differ += a.Lr[px] != b.Lr[px] || a.Lr_stderr[px] != b.Lr_stderr[px] || a.spp[px] != b.spp[px] ||
                  a.rejected[px] != b.rejected[px];
    REQUIRE(differ == 0);
}

}  // namespace

TEST_CASE("chunk sweeps, a restart from the sums, and merged shards equal one sweep bit for bit", "[render][accumulation]") {
    struct Case {
        EstimatorKind kind;
        std::uint32_t samples;
        double target;
    };
    const Case c = GENERATE(Case{EstimatorKind::exact, 1, 0.0}, Case{EstimatorKind::uniform, 37, 0.0},
                            Case{EstimatorKind::power, 24, 0.0}, Case{EstimatorKind::ris, 20, 0.0},
                            Case{EstimatorKind::tree, 8, 0.05});
    INFO(enumName(c.kind) << " " << c.samples << " samples, target " << c.target);
    Settings s = test::smallDiskSettings();
    s.render.estimator = c.kind;
    s.render.samples = c.samples;
    s.render.candidates = 4;
    s.render.target_stderr = c.target;
    s.render.max_samples = 256;
    s.render.seed = 9;
    const Particles particles = ParticleSource(s).frame(0);
    const FrameImage whole = test::renderParticles(s, particles);

    // Chunk by chunk, stopped half-way (the hook throws), restarted from a copy of the sums.
    FrameRenderer renderer(s, ParticleSource::fixed(particles), RenderOptions{true});
    Accumulation sums, saved;
    LightingSession session;
    session.result = &sums;
    int chunks = 0;
    session.afterChunk = [&](const Accumulation& acc) {
        if (++chunks == 2) {
            saved = acc;
            throw Interrupted{15};
        }
        return true;
    };
    FrameStats stats;
    const LightingPlan plan = planLighting(s.render, s.camera.height);
    if (plan.chunks() > 2) {
        REQUIRE_THROWS_AS(renderer.render(0, stats, &session), Interrupted);
        LightingSession resumed;
        resumed.resume = &saved;
        resumed.result = &sums;
        const FrameImage restarted = renderer.render(0, stats, &resumed);
        requireSameLighting(whole.lighting, restarted.lighting);
    }
    if (c.target == 0.0) {  // shards: a chunk range each, merged
        Accumulation merged;
        for (std::uint32_t i = 0; i < 3 && plan.chunks() >= 3; ++i) {
            Accumulation part;
            LightingSession shard;
            shard.shard = Shard{i, 3};
            shard.result = &part;
            renderer.render(0, stats, &shard);
            if (i == 0) merged = part;
            else merged.merge(part);
        }
        if (plan.chunks() >= 3) {
            LightingImage out;
            resolveLighting(merged, plan.exact, out);
            requireSameLighting(whole.lighting, out);
        }
    }
}

TEST_CASE("a crop holds its window alone, and its pixels, stopped and restarted, are the whole render's bit for bit",
          "[render][accumulation][window]") {
    struct Case {
        EstimatorKind kind;
        std::uint32_t samples;
        double target;
    };
    const Case c = GENERATE(Case{EstimatorKind::exact, 1, 0.0}, Case{EstimatorKind::power, 24, 0.0},
                            Case{EstimatorKind::tree, 8, 0.05}, Case{EstimatorKind::split, 20, 0.0});
    INFO(enumName(c.kind) << " " << c.samples << " samples, target " << c.target);
    Settings s = test::smallDiskSettings();
    s.render.estimator = c.kind;
    s.render.samples = c.samples;
    s.render.target_stderr = c.target;
    s.render.max_samples = 256;
    s.render.near_lights = 0;  // split: the pilot's k, the whole frame's
    s.render.seed = 5;
    const Particles particles = ParticleSource(s).frame(0);
    const FrameImage whole = test::renderParticles(s, particles);
    // Across 8x8 tile borders on every side, off the image's edges.
    const PixelWindow w{13, 38, 5, 27};
    s.render.crop = {double(w.x0), double(w.x1), double(w.y0), double(w.y1)};
    FrameRenderer renderer(s, ParticleSource::fixed(particles), RenderOptions{true});
    REQUIRE(renderer.plan().traced == w);

    // Stopped part-way (exact: after row 19, fifteen rows into the window; the
    // others: after the first band with a hit pixel done, the first bands
    // being probes of a few pixels), restarted from a copy of the sums.
    Accumulation sums, saved;
    LightingSession session;
    session.result = &sums;
    int calls = 0;
    session.afterChunk = [&](const Accumulation& acc) {
        const bool someDone = std::count(acc.n.begin(), acc.n.end(), 0u) < std::ptrdiff_t(acc.n.size());
        if (c.kind == EstimatorKind::exact ? ++calls == 20 : someDone) {
            saved = acc;
            throw Interrupted{15};
        }
        return true;
    };
    FrameStats stats;
    REQUIRE_THROWS_AS(renderer.render(0, stats, &session), Interrupted);
    CHECK(saved.window == w);
    CHECK(saved.n.size() == w.pixels());  // the sums of the window, not of the image
    CHECK(std::count(saved.n.begin(), saved.n.end(), 0u) > 0);  // stopped with work left
    CHECK(std::count(saved.n.begin(), saved.n.end(), 0u) < std::ptrdiff_t(w.pixels()));  // and some done
    LightingSession resumed;
    resumed.resume = &saved;
    resumed.result = &sums;
    const FrameImage crop = renderer.render(0, stats, &resumed);
    CHECK(crop.window == w);
    for (const std::size_t size : {crop.L.size(), crop.Le.size(), crop.lighting.Lr.size(), crop.lighting.spp.size(),
                                   crop.depth.size(), crop.normal.size(), crop.particle.size()})
        CHECK(size == w.pixels());
    std::size_t differ = 0, hits = 0;
    for (std::uint32_t y = w.y0; y < w.y1; ++y)
        for (std::uint32_t x = w.x0; x < w.x1; ++x) {
            const std::size_t a = std::size_t(y) * s.camera.width + x, b = w.index(x, y);
            hits += whole.particle[a] != kNoParticle;
            differ += whole.L[a] != crop.L[b] || whole.lighting.Lr[a] != crop.lighting.Lr[b] ||
                      whole.lighting.Lr_stderr[a] != crop.lighting.Lr_stderr[b] || whole.lighting.spp[a] != crop.lighting.spp[b] ||
                      whole.particle[a] != crop.particle[b] || whole.depth[a] != crop.depth[b];
        }
    CHECK(differ == 0);
    CHECK(hits > 50);  // the window shows the disk
}

TEST_CASE("accumulation files round-trip and refuse corruption", "[io][accumulation]") {
    const auto dir = test::scratchDir("accumulation_file");
    Accumulation a;
    const PixelWindow window{1, 4, 0, 2};  // a crop's sums: 3x2 of a 5x3 image
    a.reset(5, 3, 7, &window);
    for (std::size_t px = 0; px < a.pixels(); ++px) {
        a.sum[px] = DVec3(double(px), 0.5, -1e300);
        a.sumSq[px] = DVec3(1e-300, double(px) * 3.0, 2.0);
        a.n[px] = std::uint32_t(px * 11);
        a.done[px] = px % 2;
        a.rejected[px] = std::uint32_t(px);
    }
    AccumulationFile f{{{"kind", "test"}, {"frame", 4}}, a};
    writeAccumulationFile(dir / "a.acc", f);
    const AccumulationFile g = readAccumulationFile(dir / "a.acc");
    CHECK(g.header["kind"] == "test");
    CHECK(g.acc.width == 5);
    CHECK(g.acc.height == 3);
    CHECK(g.acc.window == window);
    CHECK(g.acc.nextChunk == 7);
    CHECK(g.acc.sum == a.sum);
    CHECK(g.acc.sumSq == a.sumSq);
    CHECK(g.acc.n == a.n);
    CHECK(g.acc.done == a.done);
    CHECK(g.acc.rejected == a.rejected);

    // Any single flipped byte is detected (checksum), as is any truncation.
    const std::string bytes = test::readFile(dir / "a.acc");
    for (std::size_t k = 0; k < bytes.size(); k += 7) {
        std::string bad = bytes;
        bad[k] ^= 0x01;
        std::ofstream(dir / "b.acc", std::ios::binary) << bad;
        INFO("byte " << k);
        CHECK_THROWS_AS(readAccumulationFile(dir / "b.acc"), InputError);
    }
    for (std::size_t size : {std::size_t(0), std::size_t(10), bytes.size() / 2, bytes.size() - 1}) {
        std::ofstream(dir / "c.acc", std::ios::binary) << bytes.substr(0, size);
        INFO("size " << size);
        CHECK_THROWS_AS(readAccumulationFile(dir / "c.acc"), InputError);
    }
}

TEST_CASE("a Monte Carlo band is sized to the stop latency: a probe first, then what fits the band time", "[render][accumulation]") {
    using accretion::nextBandPixels;
    // Before any timing: one group of 8 pixels per core, whatever the samples.
    CHECK(nextBandPixels(0.0, 8192, 0, 8, 2, 2.0) == 16);
    CHECK(nextBandPixels(0.0, 8192, 0, 8, 16, 2.0) == 128);
    // Measured: 1 ms per pixel and chunk over 100 chunks is 0.1 s a pixel:
    // 20 pixels fill 2 s.
    CHECK(nextBandPixels(1e-3, 100, 16, 8, 2, 2.0) == 20);
    // Slower than a group per core in 2 s: one group per core still.
    CHECK(nextBandPixels(1.0, 100, 16, 8, 2, 2.0) == 16);
    // Fast pixels: at most 4x the largest band so far (a band of sky does not size one of disk).
    CHECK(nextBandPixels(1e-9, 100, 16, 8, 2, 2.0) == 64);
    CHECK(nextBandPixels(1e-9, 100, 1000, 8, 2, 2.0) == 4000);
    CHECK(nextBandPixels(1e-6, 100, 1000000, 8, 2, 2.0) == 20000);
}
