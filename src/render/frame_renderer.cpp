#include "accretion/render/frame_renderer.h"

#include "accretion/render/compose_image.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <tuple>

#include <fmt/format.h>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/scene/scene_parser.h"

namespace accretion {
namespace {

/// buildClusters as a dispatch of one thread per cluster (counting mode):
/// its primitives as loop trips, particle records read, BLAS bytes written;
/// the builds as the cost model prices them (BuildCounters). The instances
/// layout is one thread per particle writing its instance record; its BLAS
/// (the unit billboard) is built once, so only the TLAS is built, or with
/// the refit policy refitted, per frame. Every other layout rebuilds its
/// small TLAS over the clusters.
void recordClusterBuild(const ParticleBvh& bvh, const Particles& particles, FrameCounters& counters) {
    const Clusters& clusters = bvh.clusters();
    const BvhStats& s = bvh.stats();
    const GeometrySettings& g = bvh.settings();
    if (g.layout == AccelLayout::instances) {
        const auto n = static_cast<std::uint32_t>(particles.size());
        PassCounters& pc = counters.add(Pass::buildClusters, n, 1);
        pc.dispatches = 1;  // the instance records
        pc.build.addTlas(n, s.refitted);
        for (ThreadCounters& t : pc.threads) {
            t.active = 1;
            t.trips = 1;
            t.bytesRead = gpu_layout::kParticleRecord;
            t.bytesWritten = 64;  // OptixInstance
        }
        return;
    }
    PassCounters& pc = counters.add(Pass::buildClusters, static_cast<std::uint32_t>(clusters.count()), 1);
    pc.dispatches = 1;  // the primitive expansion; the builds are counted apart
    const bool triangles = g.primitive == Primitive::billboard && g.layout == AccelLayout::clusters;
    const bool custom = !triangles;  // boxes or spheres
    const bool spheres = g.primitive == Primitive::sphere && g.layout == AccelLayout::clusters;  // OptiX's built-in spheres
    for (std::size_t c = 0; c < clusters.count(); ++c) {
        ThreadCounters& t = pc.threads[c];
        const auto n = static_cast<std::uint32_t>(clusters.members(c).size());
        t.active = 1;
        t.cluster = static_cast<std::uint32_t>(c);
        t.trips = triangles ? 2 * n : n;
        t.bytesRead = n * gpu_layout::kParticleRecord;
        // vertex + index buffers, sphere points, or boxes (OptixAabb)
        t.bytesWritten = triangles ? n * (4 * 12 + 2 * 12) : g.layout == AccelLayout::aabbs ? n * 24 : n * 16;
        // The partial policy rebuilds a window of the clusters: their sizes are alike, so the first ones stand in.
        if (c < s.rebuiltClusters) pc.build.addBlas(t.trips, custom, s.refitted, spheres);
    }
    pc.build.addTlas(clusters.count(), false);
}

/// The structure the CPU traces for these settings (cpuGeometry).
std::unique_ptr<ParticleBvh> newBvh(const EmbreeDevice& device, const Settings& s) {
    return std::make_unique<ParticleBvh>(device, cpuGeometry(s.geometry, s.gpu.counters), s.gpu);
}

/// composeImage (the final shading, Le + Lr) per pixel (counting mode).
void recordCompose(const GBuffer& gbuffer, const Particles& particles, const ParticleBvh& bvh, PassCounters& pc) {
    for (std::size_t px = 0; px < gbuffer.texels.size(); ++px) {
        const GBufferTexel& g = gbuffer.texels[px];
        ThreadCounters& t = pc.threads[px];
        recordTexel(t, g, particles, bvh, gpu_layout::kGBufferTexel);
        t.bytesWritten = gpu_layout::kRadiance;
        if (g.hit()) t.bytesRead += gpu_layout::kRadiance + gpu_layout::kParticleRecord;
    }
}

/// composeImage: L = Le + Lr on hits (background on misses), depth, normal
/// and particle AOVs of the G-buffer's window (composeLayers), and the
/// frame's spp statistics.
void composeImage(const GBuffer& gbuffer, const Particles& particles, const ShadingSettings& shading, FrameImage& img,
                  FrameStats& stats) {
    LightingImage& lit = img.lighting;
    const ComposeTotals t = composeLayers(gbuffer.texels, particles.emission, shading,
                                          {img.L, img.Le, img.depth, img.normal, img.particle, lit.Lr, lit.Lr_stderr, lit.rejected, lit.spp});
    if (t.nonFinite) stats.nonFinite[Pass::composeImage] += t.nonFinite;
    stats.hitPixels = t.hits;
    stats.maxSpp = std::max(stats.maxSpp, t.maxSpp);
    stats.meanSpp = t.hits ? t.sppSum / double(t.hits) : 0.0;
}

/// Cut every per-pixel layer of `img` (rendered `rendered`, a window of the
/// image) to img.window: restir and counting mode render the whole frame,
/// restir with restir.crop_margin the crop's margin too, and keep
/// render.crop's pixels. The counters stay the whole dispatch's.
void cropLayers(FrameImage& img, const PixelWindow& rendered) {
    const PixelWindow& c = img.window;
    const PixelWindow w{c.x0 - rendered.x0, c.x1 - rendered.x0, c.y0 - rendered.y0, c.y1 - rendered.y0};
    auto cut = [&](auto& layer) {
        if (!layer.empty()) layer = cropPixels(layer, rendered.width(), w);
    };
    LightingImage& lit = img.lighting;
    ReservoirImage& res = img.reservoirs;
    std::apply([&](auto&... layer) { (cut(layer), ...); },
               std::tie(img.L, img.Le, lit.Lr, lit.Lr_stderr, lit.spp, lit.rejected, img.depth, img.normal, img.particle, res.W,
                        res.M, res.light, res.p_hat));
    for (Heatmap& h : img.heatmaps) cut(h.values);
}

/// The lanes' settings with their own parts (seed, crop, crop margin) set
/// to the first lane's: equal where the lanes share everything else.
std::string sharedPart(Settings s, const Settings& first) {
    s.render.seed = first.render.seed;
    s.render.crop = first.render.crop;
    s.restir.crop_margin = first.restir.crop_margin;
    return settingsToToml(s);
}

}  // namespace

struct FrameRenderer::FrameGeometry {
    CameraPose pose;
    Camera world;                         ///< the whole image's, in frame coordinates
    Particles loaded;                     ///< this frame's, unless the scene is static
    const Particles* particles = nullptr; ///< loaded or the static ones
    AliasTable powerTable;
    LightTree lightTree;
};

FrameRenderer::FrameRenderer(const Settings& settings, ParticleSource source, RenderOptions options)
    : FrameRenderer(std::vector<Settings>{settings}, std::move(source), options) {}

FrameRenderer::FrameRenderer(std::vector<Settings> lanes, ParticleSource source, RenderOptions options)
    : cameras_(lanes.at(0).camera), source_(std::move(source)), options_(options), device_(std::make_unique<EmbreeDevice>()),
      bvh_(newBvh(*device_, lanes.at(0))) {
    const std::string shared = sharedPart(lanes.at(0), lanes[0]);
    for (std::size_t k = 1; k < lanes.size(); ++k)
        if (sharedPart(lanes[k], lanes[0]) != shared)
            throw std::invalid_argument("FrameRenderer: lanes differ in more than render.seed, render.crop and restir.crop_margin");
    for (Settings& s : lanes) {
        Lane lane{std::move(s), {}, nullptr, nullptr, nullptr};
        lane.plan = planFrame(lane.settings, FrameFacts{});
        if (lanes_.size() > 0 && lane.plan.counting)
            throw std::invalid_argument("FrameRenderer: gpu.counters counts one view's work; it takes one lane");
        const EstimatorInfo& e = estimatorInfo(lane.settings.render.estimator);
        if (e.passes == LightingPasses::voxelCache) lane.voxel = std::make_unique<VoxelCache>(lane.settings);
        else if (e.passes == LightingPasses::particleSplit) lane.split = std::make_unique<ParticleSplit>(lane.settings);
        else if (e.restirPasses()) lane.restir = std::make_unique<Restir>(lane.settings, lane.plan.keepHistory);
        lanes_.push_back(std::move(lane));
    }
}

FrameRenderer::~FrameRenderer() = default;

void FrameRenderer::prepareFrame(std::uint32_t frame, FrameGeometry& g, FrameStats& stats) {
    // Frame coordinates: the world less an origin at the frame's camera, so
    // that precision does not depend on where the scene is (docs/MODEL.md
    // section 3). Geometry that persists across frames (a static scene,
    // refit and partial builds) keeps the origin of its first build.
    const Settings& settings = lanes_[0].settings;
    const FramePlan& run = lanes_[0].plan;  // the run-wide decisions, the same in every lane
    g.pose = cameras_.pose(frame);
    const Camera world = Camera::fromPose(g.pose, settings.camera.width, settings.camera.height);
    if (!built_ || !(run.staticGeometry || run.updateInPlace)) origin_ = world.position;
    g.world = world.rebased(origin_);
    stats.origin = origin_;

    // A static scene loads its particles and builds its BVH once for all
    // frames; the plan of this frame needs the particles (do they emit?).
    FrameFacts facts;
    facts.geometryBuilt = built_ && !options_.rebuildStatic;
    if (run.loadsParticles(facts)) {  // the run's plan: this frame's is made once its particles are known
        auto t = stats.timer.scope(Pass::loadParticles);
        g.loaded = source_.frame(frame);
        for (Vec3& p : g.loaded.position) p -= origin_;
        if (run.staticGeometry) staticParticles_ = std::move(g.loaded);
    }
    g.particles = run.staticGeometry ? &staticParticles_ : &g.loaded;
    const Particles& particles = *g.particles;
    facts.emissive = emissive(particles);
    for (Lane& lane : lanes_) {
        facts.historyAvailable = lane.restir && lane.restir->hasHistory();
        lane.plan = planFrame(lane.settings, facts);
    }
    const FramePlan& plan = lanes_[0].plan;
    stats.particles = particles.size();
    if (plan.buildClusters) {
        auto t = stats.timer.scope(Pass::buildClusters);
        if (plan.previousBvh) {  // double buffer: last frame's BVH stays valid
            std::swap(bvh_, previousBvh_);
            if (!bvh_) bvh_ = newBvh(*device_, settings);
        }
        bvh_->build(particles, g.world);
        built_ = true;
    }
    stats.bvh = bvh_->stats();
    if (!plan.buildClusters) {
        stats.bvh.built = false;
        stats.bvh.rebuiltClusters = 0;
        stats.bvh.clusterSeconds = stats.bvh.blasSeconds = stats.bvh.tlasSeconds = 0.0;
    }
    if (plan.sampler != LightSamplerKind::none) {
        auto t = stats.timer.scope(Pass::buildLightSampler);
        if (plan.sampler == LightSamplerKind::power) g.powerTable = buildPowerTable(particles);
        if (plan.sampler == LightSamplerKind::tree) g.lightTree = LightTree(particles, settings.shading);
        stats.lightTreeNodes = g.lightTree.nodeCount();
    }
}

void FrameRenderer::lightFrame(Lane& lane, std::uint32_t frame, const Camera& camera, const FrameGeometry& g,
                               const GBuffer& gbuffer, const LightingSession* session, PixelTrace* trace, FrameImage& img,
                               FrameStats& stats) {
    const FramePlan& plan = lane.plan;
    const Settings& settings = lane.settings;
    const Particles& particles = *g.particles;
    const AliasTable* powerTable = plan.sampler == LightSamplerKind::power ? &g.powerTable : nullptr;
    const LightTree* lightTree = plan.sampler == LightSamplerKind::tree ? &g.lightTree : nullptr;
    const std::size_t pixels = gbuffer.texels.size();
    if (!plan.lighting) {  // nothing lights the scene: Lr = 0
        img.lighting.Lr.assign(pixels, Vec3(0.0f));
        img.lighting.Lr_stderr.assign(pixels, Vec3(0.0f));
        img.lighting.spp.assign(pixels, 0.0f);
        img.lighting.rejected.assign(pixels, 0.0f);
        return;
    }
    const std::uint32_t nearLights = plan.chooseNearLights ? chooseFrameNearLights(lane, frame, g, stats) : 0u;
    auto t = stats.timer.scope(Pass::estimateLighting);
    if (plan.voxelCache) {
        VoxelInputs in{*bvh_, particles, gbuffer, camera, settings, plan, frame, powerTable, lightTree, origin_,
                       plan.counting ? &img.counters : nullptr};
        stats.lighting = lane.voxel->render(in, img.lighting, stats.timer);
        return;
    }
    if (plan.particleSplit) {
        ParticleSplitInputs in{*bvh_, particles, gbuffer, camera, settings, plan, frame, *lightTree,
                               plan.counting ? &img.counters : nullptr};
        stats.lighting = lane.split->render(in, img.lighting, stats.timer);
        return;
    }
    if (plan.restir) {
        RestirInputs in{*bvh_, particles, gbuffer, camera, settings, plan, frame, powerTable, lightTree,
                        plan.previousBvh ? previousBvh_.get() : nullptr, plan.counting ? &img.counters : nullptr, trace};
        stats.lighting = lane.restir->render(in, img.lighting, img.reservoirs, stats.timer, stats.nonFinite, stats.reuse);
        stats.reservoirBytes = lane.restir->reservoirBytes();
        if (img.lighting.rejected.empty()) img.lighting.rejected.assign(pixels, 0.0f);
        return;
    }
    LightingInputs in{*bvh_, particles, gbuffer, settings.shading, settings.render, frame, powerTable, lightTree,
                      plan.counting ? &img.counters.add(Pass::estimateLighting, camera.width, camera.height) : nullptr, trace};
    in.nearLights = nearLights;
    const LightingPlan lp = planLighting(settings.render, camera.height, session ? session->shard : Shard{});
    // Progress by work: the hit pixels of the rows (exact) or the chunks
    // (samples) still to run, as the sweep counts them.
    const Accumulation* resume = session ? session->resume : nullptr;
    const std::uint64_t firstChunk = resume ? resume->nextChunk : lp.begin;
    std::uint64_t work = 0;
    const PixelWindow& w = gbuffer.window;
    for (std::uint32_t y = w.y0; y < w.y1; ++y) {
        if (lp.exact && (y / LightingPlan::kChunkRows < firstChunk || y / LightingPlan::kChunkRows >= lp.end)) continue;
        for (std::uint32_t x = w.x0; x < w.x1; ++x) {
            // Monte Carlo: the pixels before the band cursor are done (Accumulation::bandRows, bandCols).
            if (!lp.exact && resume && (y < resume->bandRows || (y == resume->bandRows && x < resume->bandCols))) continue;
            work += gbuffer.at(x, y).hit();
        }
    }
    if (!lp.exact) work *= lp.end > firstChunk ? lp.end - firstChunk : 0;
    Progress progress(fmt::format("frame {} {}", frame, passName(Pass::estimateLighting)), work, options_.quiet);
    if (!session) {
        stats.lighting = estimateLighting(in, img.lighting, &progress);
    } else {  // in chunks, from a checkpoint, into the session's sums
        Accumulation local;
        Accumulation& acc = session->result ? *session->result : local;
        if (session->resume) acc = *session->resume;
        else acc.reset(camera.width, camera.height, lp.begin, &gbuffer.window);
        stats.lighting = accumulateLighting(in, lp, acc, session->afterChunk, &progress);
        resolveLighting(acc, lp.exact, img.lighting, &stats.lighting.nonFinite);
    }
    if (stats.lighting.nonFinite) stats.nonFinite[Pass::estimateLighting] = stats.lighting.nonFinite;
}

std::uint32_t FrameRenderer::chooseFrameNearLights(const Lane& lane, std::uint32_t frame, const FrameGeometry& g,
                                                   FrameStats& stats) {
    auto t = stats.timer.scope(Pass::chooseNearLights);
    // The pilot's image: the frame's view at 64 pixels across, whatever the
    // resolution or crop, so that every part of one image gets one k.
    const Settings& settings = lane.settings;
    constexpr std::uint32_t kWidth = 64;
    const std::uint32_t height = std::max(1u, static_cast<std::uint32_t>(std::lround(
        double(kWidth) * settings.camera.height / settings.camera.width)));
    const Camera camera = Camera::fromPose(g.pose, kWidth, height).rebased(origin_);
    GBuffer gbuffer;
    traceGBuffer(*bvh_, *g.particles, camera, settings.shading.model, gbuffer);
    const LightTree* lightTree = lane.plan.sampler == LightSamplerKind::tree ? &g.lightTree : nullptr;
    const LightingInputs pilot{*bvh_, *g.particles, gbuffer, settings.shading, settings.render, frame, nullptr, lightTree};
    stats.nearLights = chooseNearLights(pilot);
    return stats.nearLights.k;
}

FrameImage FrameRenderer::renderLane(Lane& lane, std::uint32_t frame, const FrameGeometry& g, FrameStats& stats,
                                     const LightingSession* session, PixelTrace* trace) {
    const FramePlan& plan = lane.plan;
    const Settings& settings = lane.settings;
    const Particles& particles = *g.particles;
    PassTimer& timer = stats.timer;
    // The lane's image: the whole, or restir's window of it (plan.frameWindow).
    const PixelWindow fw = plan.frameWindow;
    const bool whole = fw.isWhole(g.world.width, g.world.height);
    const Camera camera = whole ? g.world : g.world.window(fw.x0, fw.y0, fw.width(), fw.height());
    FrameImage img;
    img.camera = g.pose;
    if (plan.counting) recordClusterBuild(*bvh_, particles, img.counters);

    // A crop traces, lights and holds only its window, each pixel as in the
    // whole image: every estimator but restir lights a pixel from its own
    // streams alone. restir and counting mode render everything (FramePlan::traced).
    img.window = PixelWindow::of(settings);
    const PixelWindow& traced = plan.traced;
    GBuffer gbuffer;
    {
        auto t = timer.scope(Pass::traceGBuffer);
        PassCounters* pc = plan.counting ? &img.counters.add(Pass::traceGBuffer, camera.width, camera.height) : nullptr;
        stats.primaryRays = traceGBuffer(*bvh_, particles, camera, settings.shading.model, gbuffer, pc, &traced);
    }
    img.width = camera.width;
    img.height = camera.height;
    lightFrame(lane, frame, camera, g, gbuffer, session, trace, img, stats);
    {
        auto t = timer.scope(Pass::composeImage);
        composeImage(gbuffer, particles, settings.shading, img, stats);
        if (plan.counting) recordCompose(gbuffer, particles, *bvh_, img.counters.add(Pass::composeImage, img.width, img.height));
    }
    if (plan.counting) {
        img.counters.accel = bvh_->accelCounters();
        img.heatmaps = counterHeatmaps(img.counters, img.width, img.height);
    }
    if (!whole) {  // the layers are the window's: cut to render.crop, in the image's coordinates
        cropLayers(img, fw);
        img.width = g.world.width;
        img.height = g.world.height;
    } else if (traced != img.window) {
        cropLayers(img, PixelWindow::whole(img.width, img.height));
    }
    return img;
}

FrameImage FrameRenderer::render(std::uint32_t frame, FrameStats& stats, const LightingSession* session, PixelTrace* trace) {
    if (lanes_.size() != 1) throw std::logic_error("FrameRenderer::render: one lane; renderLanes renders several");
    const auto start = std::chrono::steady_clock::now();
    stats.frame = frame;
    FrameGeometry g;
    prepareFrame(frame, g, stats);
    FrameImage img = renderLane(lanes_[0], frame, g, stats, session, trace);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return img;
}

std::vector<FrameImage> FrameRenderer::renderLanes(std::uint32_t frame, FrameStats& shared, std::vector<FrameStats>& laneStats) {
    auto since = [](auto start) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    const auto start = std::chrono::steady_clock::now();
    shared.frame = frame;
    FrameGeometry g;
    prepareFrame(frame, g, shared);
    laneStats.assign(lanes_.size(), FrameStats{});
    std::vector<FrameImage> images;
    images.reserve(lanes_.size());
    for (std::size_t k = 0; k < lanes_.size(); ++k) {
        const auto laneStart = std::chrono::steady_clock::now();
        FrameStats& s = laneStats[k];
        s.frame = frame;
        s.origin = shared.origin;
        s.particles = shared.particles;
        s.bvh = shared.bvh;
        s.lightTreeNodes = shared.lightTreeNodes;
        images.push_back(renderLane(lanes_[k], frame, g, s, nullptr, nullptr));
        s.seconds = since(laneStart);
    }
    shared.seconds = since(start);
    return images;
}

}  // namespace accretion
