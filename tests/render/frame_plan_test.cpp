// Only the work a scene needs: the pass plan, and the counters that show the
// skipped work really is not done (no shadow rays, no any-hit calls, one BVH
// build for a static scene, no history for one frame, no lighting for albedo 0).
#include <algorithm>
#include <map>

#include <catch2/catch.hpp>

#include "accretion/render/frame_renderer.h"
#include "accretion/render/frame_plan.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

const PlannedStep& step(const FramePlan& plan, Pass pass) {
    if (const PlannedStep* s = plan.find(pass)) return *s;
    FAIL("no step " << passName(pass));
    return plan.steps.front();
}

/// A line of work inside a pass ("shadow rays", "counters").
const PlannedStep& step(const FramePlan& plan, std::string_view work) {
    for (const PlannedStep& s : plan.steps)
        if (!s.pass && s.work == work) return s;
    FAIL("no step " << work);
    return plan.steps.front();
}

std::vector<FrameStats> render(const Settings& s, std::vector<FrameImage>* images = nullptr) {
    FrameRenderer r(s, ParticleSource(s), RenderOptions{true});
    std::vector<FrameStats> stats;
    for (std::uint32_t f = 0; f < s.render.frames; ++f) {
        FrameStats fs;
        FrameImage img = r.render(s.render.frame_start + f, fs);
        if (images) images->push_back(std::move(img));
        stats.push_back(std::move(fs));
    }
    return stats;
}

/// The plan of a run's first frame (its particles emit).
FramePlan planPasses(const Settings& s) { return planFrame(s, FrameFacts{}); }

Settings small() {
    Settings s = accretion::test::smallDiskSettings();
    s.render.estimator = EstimatorKind::uniform;
    s.render.samples = 2;
    return s;
}

}  // namespace

TEST_CASE("visibility off: no shadow rays planned or traced, and more light", "[plan]") {
    Settings s = small();
    const auto with = render(s);
    s.shading.visibility = false;
    const FramePlan plan = planPasses(s);
    CHECK_FALSE(step(plan, "shadow rays").workRuns);
    CHECK_THAT(step(plan, "shadow rays").why, Catch::Contains("visibility off"));
    std::vector<FrameImage> img;
    const auto without = render(s, &img);
    CHECK(with[0].lighting.shadowRays > 0);
    CHECK(without[0].lighting.shadowRays == 0);
    CHECK(without[0].lighting.lightTerms > 0);
    for (EstimatorKind e : {EstimatorKind::exact, EstimatorKind::ris, EstimatorKind::restir}) {
        s.render.estimator = e;
        CHECK(render(s)[0].lighting.shadowRays == 0);
    }
}

TEST_CASE("no alpha test: no filter callbacks, disc alpha: any-hits counted", "[plan][gpu]") {
    Settings s = small();
    s.gpu.counters = true;
    CHECK_FALSE(step(planPasses(s), "alpha filter callbacks").workRuns);
    auto anyHits = [](const Settings& st) {
        FrameRenderer r(st, ParticleSource(st), RenderOptions{true});
        FrameStats fs;
        const FrameImage img = r.render(0, fs);
        std::uint64_t n = 0;
        for (const PassCounters& p : img.counters.passes)
            for (const ThreadCounters& t : p.threads) n += t.anyHits;
        return n;
    };
    CHECK(anyHits(s) == 0);
    s.geometry.alpha = AlphaMode::disc;
    CHECK(step(planPasses(s), "alpha filter callbacks").workRuns);
    CHECK(anyHits(s) > 0);
}

TEST_CASE("static particles and camera: one BVH build for all frames, the same image", "[plan]") {
    Settings s = small();
    s.particles.gm = 0.0;
    s.render.estimator = EstimatorKind::exact;
    s.render.frames = 3;
    const FramePlan plan = planPasses(s);
    CHECK(plan.staticGeometry);
    CHECK_THAT(step(plan, Pass::buildClusters).why, Catch::Contains("once for all frames"));
    std::vector<FrameImage> img;
    const auto stats = render(s, &img);
    CHECK(stats[0].bvh.built);
    CHECK_FALSE(stats[1].bvh.built);
    CHECK_FALSE(stats[2].bvh.built);
    CHECK_FALSE(stats[2].timer.ran(Pass::buildClusters));
    CHECK(img[2].L == img[0].L);
    // Moving particles rebuild every frame.
    s.particles.gm = 20.0;
    CHECK_FALSE(planPasses(s).staticGeometry);
    const auto moving = render(s);
    CHECK(moving[2].bvh.built);
}

TEST_CASE("restir: one frame or temporal off keeps no history, one neighbour-less frame skips spatial", "[plan][restir]") {
    Settings s = small();
    s.render.estimator = EstimatorKind::restir;
    s.render.frames = 1;
    CHECK_FALSE(planPasses(s).keepHistory);
    CHECK_THAT(step(planPasses(s), Pass::temporalResampling).why, Catch::Contains("one frame"));
    s.render.frames = 3;
    CHECK(planPasses(s).keepHistory);
    const auto kept = render(s);
    CHECK(kept[2].timer.runs(Pass::temporalResampling) == 1);
    s.restir.temporal = false;
    CHECK_THAT(step(planPasses(s), Pass::temporalResampling).why, Catch::Contains("temporal off"));
    const auto none = render(s);
    CHECK_FALSE(none[2].timer.ran(Pass::temporalResampling));
    CHECK(none[2].lighting.reuse.offered() > 0);  // spatial still runs
    s.restir.spatial_neighbours = 0;
    CHECK_FALSE(planPasses(s).runs(Pass::spatialResampling));
    CHECK(render(s)[2].lighting.reuse.offered() == 0);
}

TEST_CASE("albedo 0: no lighting passes, exact: no reservoirs, counters off: no counting code", "[plan]") {
    Settings s = small();
    s.shading.albedo = Vec3(0.0f);
    const FramePlan plan = planPasses(s);
    CHECK_FALSE(plan.lighting);
    CHECK_FALSE(plan.runs(Pass::estimateLighting));
    CHECK_FALSE(plan.runs(Pass::buildLightSampler));
    const auto stats = render(s);
    CHECK(stats[0].lighting.shadowRays == 0);
    CHECK(stats[0].lighting.lightTerms == 0);
    s.shading.albedo = Vec3(0.8f);
    s.render.estimator = EstimatorKind::exact;
    CHECK_THAT(step(planPasses(s), "reservoirs").why, Catch::Contains("no reservoirs"));
    CHECK_THAT(step(planPasses(s), "counters").why, Catch::Contains("no counting code"));
    s.gpu.counters = true;
    CHECK(step(planPasses(s), "counters").workRuns);
}

TEST_CASE("the plan is the frame: every frame's timed passes are exactly the plan's, for every skip", "[plan]") {
    // Each variant skips something (or runs something more); every frame of
    // it must time exactly the passes its plan lists, in the plan's names.
    struct Variant {
        const char* name;
        void (*apply)(Settings&);
    };
    const Variant variants[] = {
        {"uniform", [](Settings&) {}},
        {"visibility off", [](Settings& s) { s.shading.visibility = false; }},
        {"albedo 0", [](Settings& s) { s.shading.albedo = Vec3(0.0f); }},
        {"no emission", [](Settings& s) { s.particles.luminosity = 0.0; }},
        {"static", [](Settings& s) { s.particles.gm = 0.0; }},
        {"power", [](Settings& s) { s.render.estimator = EstimatorKind::power; }},
        {"tree", [](Settings& s) { s.render.estimator = EstimatorKind::tree; }},
        {"split, the pilot's k", [](Settings& s) { s.render.estimator = EstimatorKind::split; s.render.near_lights = 0; }},
        {"split, k = 8", [](Settings& s) { s.render.estimator = EstimatorKind::split; s.render.near_lights = 8; }},
        {"ris power", [](Settings& s) { s.render.estimator = EstimatorKind::ris; s.render.source = LightSource::power; }},
        {"ris tree", [](Settings& s) { s.render.estimator = EstimatorKind::ris; s.render.source = LightSource::tree; }},
        {"restir tree", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.render.source = LightSource::tree; }},
        {"restir", [](Settings& s) { s.render.estimator = EstimatorKind::restir; }},
        {"restir temporal off", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.restir.temporal = false; }},
        {"restir no neighbours", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.restir.spatial_neighbours = 0; }},
        {"restir no iterations", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.restir.spatial_iterations = 0; }},
        {"restir half scale", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.restir.resolution_scale = 0.5; }},
        {"restir visibility off", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.shading.visibility = false; }},
        {"restir static", [](Settings& s) { s.render.estimator = EstimatorKind::restir; s.particles.gm = 0.0; }},
        {"particle_restir, world neighbours x 2",
         [](Settings& s) {
             s.render.estimator = EstimatorKind::particle_restir;
             s.render.source = LightSource::tree;
             s.restir.spatial_neighbours = 3;
             s.restir.spatial_iterations = 2;
         }},
        {"particle_restir, pixels resampled",
         [](Settings& s) {
             s.render.estimator = EstimatorKind::particle_restir;
             s.restir.pixel_shading = PixelShading::resample;
         }},
        {"voxel_cache", [](Settings& s) { s.render.estimator = EstimatorKind::voxel_cache; s.render.source = LightSource::tree; }},
        {"particle_split", [](Settings& s) { s.render.estimator = EstimatorKind::particle_split; }},
    };
    for (const Variant& v : variants) {
        Settings s = small();
        s.render.frames = 3;
        v.apply(s);
        FrameRenderer r(s, ParticleSource(s), RenderOptions{true});
        for (std::uint32_t f = 0; f < s.render.frames; ++f) {
            FrameStats fs;
            r.render(f, fs);
            std::vector<Pass> timed;
            for (const auto& [pass, seconds] : fs.timer.all()) timed.push_back(pass);
            std::vector<Pass> planned = r.plan().passes();
            std::sort(planned.begin(), planned.end());
            INFO(v.name << ", frame " << f << "\n" << formatPlan(r.plan()));
            CHECK(timed == planned);
        }
    }
    // particle_restir's spatial reuse is its world-neighbour pass, restir's the screen disc: never both.
    Settings w = small();
    w.render.estimator = EstimatorKind::particle_restir;
    w.restir.spatial_neighbours = 3;
    const FramePlan particles = planFrame(w, FrameFacts{false, true, true});
    CHECK(particles.runs(Pass::resampleWorldNeighbours));
    CHECK_FALSE(particles.runs(Pass::spatialResampling));
    w.render.estimator = EstimatorKind::restir;
    const FramePlan pixels = planFrame(w, FrameFacts{false, true, true});
    CHECK(pixels.runs(Pass::spatialResampling));
    CHECK_FALSE(pixels.runs(Pass::resampleWorldNeighbours));
    // particle_restir's pixels interpolate (shadeParticlePixels, after the
    // texels' shadow rays) or resample and trace (resampleParticlePixels, the
    // texels tracing none): one pass or the other, and the rays where they are traced.
    for (const PixelShading shading : {PixelShading::interpolate, PixelShading::resample}) {
        Settings p = small();
        p.render.estimator = EstimatorKind::particle_restir;
        p.restir.pixel_shading = shading;
        p.gpu.counters = true;
        const bool resample = shading == PixelShading::resample;
        INFO(enumName(shading));
        FrameRenderer r(p, ParticleSource(p), RenderOptions{true});
        FrameStats fs;
        const FrameImage img = r.render(0, fs);
        CHECK(r.plan().runs(Pass::resampleParticlePixels) == resample);
        CHECK(r.plan().runs(Pass::shadeParticlePixels) == !resample);
        CHECK(r.plan().runs(Pass::traceShadowRays) == !resample);
        std::map<Pass, std::uint64_t> rays;
        for (const PassCounters& c : img.counters.passes)
            for (const ThreadCounters& t : c.threads) rays[c.pass] += t.rays;
        CHECK(rays.contains(Pass::resampleParticlePixels) == resample);
        CHECK(rays.contains(Pass::shadeParticlePixels) == !resample);
        CHECK(rays[resample ? Pass::resampleParticlePixels : Pass::traceShadowRays] > 0);
        CHECK(rays[Pass::shadeParticlePixels] == 0);
    }
    // And the plan says what it skips: frame 0 of restir has no history yet, frame 1 does.
    Settings s = small();
    s.render.estimator = EstimatorKind::restir;
    s.render.frames = 3;
    CHECK_FALSE(planFrame(s, FrameFacts{}).temporal);
    CHECK(planFrame(s, FrameFacts{false, true, true}).temporal);
    CHECK_FALSE(planFrame(s, FrameFacts{false, true, false}).lighting);
    // The candidates' source decides the light sampler built.
    for (const auto& [source, sampler] : {std::pair{LightSource::uniform, LightSamplerKind::none},
                                          std::pair{LightSource::power, LightSamplerKind::power},
                                          std::pair{LightSource::tree, LightSamplerKind::tree}}) {
        s.render.source = source;
        CHECK(planFrame(s, FrameFacts{false, true, true}).sampler == sampler);
    }
}

TEST_CASE("restir sources tiles and regir: their presampling passes run, are timed and counted, only when asked for", "[plan][restir][gpu]") {
    Settings s = small();
    s.render.estimator = EstimatorKind::restir;
    s.gpu.counters = true;
    s.restir.tile_count = 6;
    s.restir.tile_size = 40;
    s.restir.regir_cells = 3;
    s.restir.regir_lights_per_cell = 20;
    s.restir.regir_build_samples = 5;
    const auto passesOf = [](const Settings& st) {
        FrameRenderer r(st, ParticleSource(st), RenderOptions{true});
        FrameStats fs;
        FrameImage img = r.render(0, fs);
        return std::make_pair(std::move(img.counters.passes), fs);
    };
    for (const LightSource src : {LightSource::power, LightSource::tiles, LightSource::regir}) {
        INFO(enumName(src));
        s.render.source = src;
        const FramePlan plan = planPasses(s);
        const bool tiles = src != LightSource::power, regir = src == LightSource::regir;
        CHECK(plan.runs(Pass::presampleLightTiles) == tiles);
        CHECK(plan.runs(Pass::presampleRegirGrid) == regir);
        CHECK(plan.sampler == LightSamplerKind::power);  // the tiles are drawn from the power table
        const auto [passes, stats] = passesOf(s);
        CHECK(stats.timer.runs(Pass::presampleLightTiles) == unsigned(tiles));
        CHECK(stats.timer.runs(Pass::presampleRegirGrid) == unsigned(regir));
        std::size_t seen = 0;
        for (const PassCounters& p : passes) {
            std::uint64_t active = 0, trips = 0, written = 0;
            for (const ThreadCounters& t : p.threads) {
                active += t.active;
                trips += t.trips;
                written += t.bytesWritten;
            }
            if (p.pass == Pass::presampleLightTiles) {  // one thread per entry: one draw, an 8-byte entry
                ++seen;
                CHECK((p.width == 40 && p.height == 6));
                CHECK(active == 240);
                CHECK(trips == 240);
                CHECK(written == 240 * 8);
            }
            if (p.pass == Pass::presampleRegirGrid) {  // one thread per slot: 5 candidates, an 8-byte slot
                ++seen;
                CHECK((p.width == 20 && p.height == 27));
                CHECK(active == 540);
                CHECK(trips == 540 * 5);
                CHECK(written == 540 * 8);
            }
        }
        CHECK(seen == std::size_t(tiles) + std::size_t(regir));
    }
}

TEST_CASE("every estimator and source: the plan builds the light sampler the estimator draws from, and no other", "[plan]") {
    // What each estimator draws from, spelled out here rather than read from
    // the estimator table: tree and split their light tree, power its alias
    // table, ris and restir their render.source's (tiles and the ReGIR grid
    // are presampled from the power table).
    for (const EstimatorKind e : {EstimatorKind::exact, EstimatorKind::uniform, EstimatorKind::power, EstimatorKind::ris,
                                  EstimatorKind::restir, EstimatorKind::tree, EstimatorKind::split})
        for (const LightSource src : {LightSource::uniform, LightSource::power, LightSource::tree, LightSource::tiles,
                                      LightSource::regir}) {
            const bool resampling = e == EstimatorKind::ris || e == EstimatorKind::restir;
            if (e == EstimatorKind::ris && (src == LightSource::tiles || src == LightSource::regir)) continue;  // refused
            if (!resampling && src != LightSource::uniform) continue;  // the source is not read
            Settings s = small();
            s.render.estimator = e;
            s.render.source = src;
            s.render.samples = 2;
            const LightSamplerKind expected =
                e == EstimatorKind::tree || e == EstimatorKind::split || (resampling && src == LightSource::tree) ? LightSamplerKind::tree
                : e == EstimatorKind::power || (resampling && src != LightSource::uniform)                       ? LightSamplerKind::power
                                                                                                                  : LightSamplerKind::none;
            INFO(enumName(e) << " from " << enumName(src));
            CHECK(planPasses(s).sampler == expected);
            const auto stats = render(s);  // a sampler missing for its estimator is an internal error
            CHECK((stats[0].lightTreeNodes > 0) == (expected == LightSamplerKind::tree));
            CHECK(stats[0].timer.ran(Pass::buildLightSampler) == (expected != LightSamplerKind::none));
        }
}

TEST_CASE("restir on a crop with a margin: the window traced is the crop and its margin on the 8-pixel grid, within the image",
          "[plan][restir][window]") {
    Settings s;
    s.camera.width = 200;
    s.camera.height = 100;
    s.render.estimator = EstimatorKind::restir;
    s.render.crop = {50, 90, 3, 40};
    const PixelWindow whole = PixelWindow::whole(200, 100);
    CHECK(planFrame(s, FrameFacts{}).frameWindow == whole);  // no margin: the whole frame, cut afterwards
    CHECK(planFrame(s, FrameFacts{}).traced == whole);
    s.restir.crop_margin = 20;
    const FramePlan p = planFrame(s, FrameFacts{});
    CHECK(p.frameWindow == PixelWindow{24, 112, 0, 64});  // 30 -> 24, 110 -> 112, -17 -> 0, 60 -> 64
    CHECK(p.traced == PixelWindow::whole(88, 64));
    CHECK_THAT(formatPlan(p), Catch::Contains("the 88x64 window at (24, 0)"));
    s.restir.crop_margin = 1000;  // beyond the image on every side: the whole frame
    CHECK(planFrame(s, FrameFacts{}).frameWindow == whole);
    s.render.estimator = EstimatorKind::split;  // a crop of any other estimator renders alone, the margin unused
    CHECK(planFrame(s, FrameFacts{}).traced == PixelWindow::of(s));
    CHECK(planFrame(s, FrameFacts{}).frameWindow == whole);
}
