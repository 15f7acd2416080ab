// accretion-optix: the OptiX twin of the GPU pipeline. It reads
// the scene files, particle buffers and settings `accretion render` reads,
// runs the pipeline on the GPU (per-frame cluster BLAS builds, TLAS,
// G-buffer raygen, lighting) and writes per frame a .gpuframe (the layers
// render writes; `accretion import-gpu` makes render's EXR of it), the
// per-pass GPU times (CUDA events, median of --repeat launches) as
// calibrate's timings CSV, and a stats JSON.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/scene/estimator_table.h"
#include "accretion/core/atomic_file.h"
#include "accretion/core/csv_cell.h"
#include "accretion/core/error.h"
#include "accretion/core/median.h"
#include "accretion/core/parse.h"
#include "accretion/core/version.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/geometry/clustering.h"
#include "accretion/io/gpu_frame_file.h"
#include "accretion/io/provenance.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/accumulation.h"
#include "accretion/render/compose_image.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/upsample_pixel.h"
#include "accretion/scene/scene_parser.h"
#include "launch_params.h"
#include "gather_particle_texels.h"
#include "optix_pipeline.h"
#include "particle_accel.h"
#include "accretion/render/voxel_grid.h"
#include "restir_kernels.h"
#include "split_kernels.h"
#include "voxel_kernels.h"

#ifndef ACCRETION_TWIN_PROGRAMS
#define ACCRETION_TWIN_PROGRAMS "programs.optixir"
#endif

namespace accretion::twin {

/// twin --ray-launch: the threads of a launch of a thread per ray of each
/// item (updateVoxelCache's cells, shadeSplitTexels' texels).
enum class RayLaunch {
    texels,  ///< one row: a cell's rays side by side; a texel's near rays, then its far ones (splitRayThread)
    linear,  ///< one row: the same cells; a split ray of every texel, then the next
    rows     ///< the linear order as a 2D launch, which OptiX tiles onto warps and blocks
};

/// twin --shadow-rays: how restir's traceShadowRays traces.
enum class ShadowRays {
    trace,     ///< optixTrace (the pipeline)
    traverse,  ///< optixTraverse and a hit object (inline-like)
    reorder    ///< optixTraverse after optixReorder by the SER key
};

}  // namespace accretion::twin

namespace accretion {
ACC_ENUM_NAMES(twin::RayLaunch, "texels", "linear", "rows");
ACC_ENUM_NAMES(twin::ShadowRays, "trace", "traverse", "reorder");
}  // namespace accretion

namespace accretion::twin {
namespace {

/// An option naming a value of E (its names: ACC_ENUM_NAMES), refused unless it is one, read by parseEnum.
template <class E>
CLI::Option* addEnumOption(CLI::App& app, const std::string& name, E& out, const std::string& doc) {
    const auto& names = EnumNames<E>::names;
    return app.add_option_function<std::string>(name, [&out](const std::string& v) { parseEnum(v, out); }, doc)
        ->check(CLI::IsMember(std::vector<std::string>(names.begin(), names.end())));
}

struct Args {
    std::string scene;
    std::vector<std::string> defines;
    std::string frames, output, timings, config, programs = ACCRETION_TWIN_PROGRAMS;
    ShadowRays shadowRays = ShadowRays::trace;
    RayLaunch rayLaunch = RayLaunch::texels;
    unsigned repeat = 5, buildStreams = 1, buildThreads = 1, seeds = 1;
    bool perBlas = false, compact = false, quiet = false, validation = false, skipLighting = false, lrOnly = false;
};

/// The settings the twin runs; anything else is refused by name.
void requireSupported(const Settings& s, bool lighting) {
    auto refuse = [](const std::string& what) {
        throw InputError(fmt::format("accretion-optix does not run {} yet (the CPU renderer does)", what));
    };
    const GeometrySettings& g = s.geometry;
    if (g.primitive == Primitive::sphere && g.layout != AccelLayout::clusters)
        refuse(fmt::format("geometry.primitive = \"sphere\" with geometry.layout = \"{}\" (spheres: clusters)", enumName(g.layout)));
    if (g.primitive == Primitive::sphere && g.alpha != AlphaMode::opaque) refuse("geometry.alpha on spheres");
    // Micromaps on boxes and cluster policies on instances are no design at
    // all: the scene's rules refuse them for every command (loadScene).
    const EstimatorKind e = s.render.estimator;
    if (lighting && !estimatorInfo(e).twin) refuse(fmt::format("render.estimator = \"{}\"", enumName(e)));
    if (lighting && estimatorInfo(e).restirPasses()) {
        const RestirSettings& r = s.restir;
        if (!sourceInfo(s.render.source).twin) refuse(fmt::format("render.source = \"{}\"", enumName(s.render.source)));
        if (r.layout != ReservoirLayout::full) refuse("restir.layout = \"packed\"");
        if (r.basic_visibility) refuse("restir.basic_visibility");
        if (r.candidate_visibility) refuse("restir.candidate_visibility");
    }
    if (!s.render.crop.empty()) refuse("render.crop");
}

/// The particle arrays the programs read, on the device.
struct FrameBuffers {
    DeviceBuffer position, emission, albedo, radius, dmin2, frames, gbuffer, Lr, counters, params;
    // restir: two reservoir buffers, rejections, the BLAS of each particle,
    // and the previous frame (temporal reuse).
    DeviceBuffer resA, resB, rejected, particleCluster;
    DeviceBuffer gridGbuffer, gridLr;  // restir.resolution_scale < 1 or particle_restir: the lighting grid
    DeviceBuffer gatherFlags, gatherIds, gatherSortedIds, gatherKeys, gatherSortedKeys, gatherCount, gatherTemp, slotOf;  // particle_restir
    DeviceBuffer prevSlotOf, prevTexelLr;
    DeviceBuffer splitFar, prevSplitFar;  ///< particle_split.history_of far: the texels' far means' average, this frame's and last
    DeviceBuffer splitAge, prevSplitAge;  ///< particle_split.history_start mean: the far rays (frames) each texel has averaged
    DeviceBuffer prevSplitNear, prevSplitNearFound, splitTexelNear, prevSplitTexelNear;  ///< particle_split.far_handoff: last frame's near sets; the texels' near terms
    DeviceBuffer prevPosition, prevEmission, prevAlbedo, prevDmin2, prevGbuffer, prevReservoirs;
    DeviceBuffer aliasProb, aliasAlias, aliasPmf;  // power: the alias table
    DeviceBuffer treeNodes, treePaths;            // tree: the light tree's nodes; particle_split: each light's path
    DeviceBuffer Lr_stderr, spp, rejectedSamples;  // uniform / power
    DeviceBuffer voxelCells[2], voxelOccupied, voxelRays;  // voxel_cache: last frame's cells and this frame's; the reached cells; their rays
    DeviceBuffer splitNear, splitNearFound, splitNearRadius2, splitRays;  // particle_split: each visible particle's near lights; the texels' rays
    DeviceBuffer splitNewFlags, splitNewIds, splitNewTexels, splitNewCount, splitSelectTemp;  // particle_split.far_new's select
};

void copyDevice(DeviceBuffer& to, const DeviceBuffer& from, std::size_t bytes, cudaStream_t stream) {
    to.reserve(bytes);
    CUDA_CHECK(cudaMemcpyAsync(to.as<void>(), from.as<void>(), bytes, cudaMemcpyDeviceToDevice, stream));
}

/// Medians of a frame's timed steps (GpuTimer names), in ms.
using StepTimes = std::map<std::string, std::vector<double>>;

/// A run of the twin: the device state kept from frame to frame, and the
/// frame's plan (the CPU's FramePlan, planned from the same settings and
/// facts) executed pass by pass on the GPU.
class TwinRun {
public:
    TwinRun(const Args& a, const Settings& settings);
    ~TwinRun() { cudaStreamDestroy(stream_); }
    TwinRun(const TwinRun&) = delete;
    TwinRun& operator=(const TwinRun&) = delete;

    /// The next seed's run starts from scratch: no BVH, no history.
    void restart() {
        history_ = built_ = false;
        prevCount_ = 0;
        voxelPlacement_ = VoxelPlacement{};
        splitHistory_ = false;
    }
    /// Render, time and write one frame (a .gpuframe and its stats record).
    void renderFrame(std::uint32_t frame, std::uint64_t seed);
    /// The run's stats JSON and, with --timings, the last frame's timings CSV.
    void writeRunOutputs() const;

private:
    Particles particlesOf(std::uint32_t frame);
    FramePlan planFrameAndLoad(std::uint32_t frame);
    void uploadParticles(const Particles& particles, const Camera& camera);
    void uploadClusterHint(const Particles& particles, bool recluster, bool first);
    LaunchParams launchParams(const FramePlan& plan, const Camera& camera, const Particles& particles,
                              std::uint32_t frame, std::uint64_t seed);
    StoredReservoir* runRestir(const FramePlan& plan, LaunchParams& lp);
    void placeVoxels(const Particles& particles);
    void runVoxelCache(LaunchParams& lp);
    void launchRays(Raygen r, std::size_t threads, unsigned rowWidth);
    std::uint32_t gatherTexels(const LaunchParams& lp, std::uint32_t side, std::uint32_t layers, const TexelPointRule& points);
    void runParticleSplit(LaunchParams& lp);
    void keepSplitHistory(std::size_t n);
    StepTimes runPasses(const FramePlan& plan, LaunchParams& lp, const Clusters& clusters, bool recluster,
                        LaunchCounters& counters, StoredReservoir*& finalReservoirs);
    void keepHistory(const Camera& camera, std::size_t particleCount, const StoredReservoir* finalReservoirs);
    GpuFrame composeFrame(const FramePlan& plan, const Particles& particles, std::uint32_t frame, const CameraPose& pose,
                          std::size_t& hits, std::size_t& nonFinite) const;

    const Args& a_;
    const Settings& s_;
    const std::string settingsToml_;
    const ParticleSource source_;
    const CameraTrack cameras_;
    const std::uint32_t W_, H_;
    const FramePlan runPlan_;  ///< the run-wide decisions (buffers, history)
    const bool sampling_;      ///< uniform / power: stderr, spp and rejections per pixel (zero when unlit)
    const LightingPlan lightingPlan_;
    AccelOptions accelOptions_;
    const bool omm_;
    Raygen shade_ = Raygen::shade;
    std::uint32_t gridW_, gridH_;  ///< restir's lighting grid (resolution_scale; particle_restir: this frame's texels)
    MortonFrame morton_;           ///< particle_restir: the Morton cube of this frame's particles
    std::string device_;
    std::unique_ptr<TwinPipeline> pipeline_;
    cudaStream_t stream_{};
    std::unique_ptr<GpuTimer> timer_;
    std::unique_ptr<ParticleAccel> accel_;
    FrameBuffers buf_;
    // Across frames.
    bool history_ = false, built_ = false;
    Camera prevCamera_{};
    std::uint32_t prevCount_ = 0;
    Clusters clusters_;
    Vec3 origin_{0.0f};
    VoxelPlacement voxelPlacement_;  ///< voxel_cache: where its grid lies (the CPU's VoxelCache's rule)
    unsigned voxelLast_ = 0;         ///< voxel_cache: buf_.voxelCells[voxelLast_] holds last frame's cells
    std::size_t splitVisible_ = 0;   ///< particle_split: this frame's visible particles (slots), for keepSplitHistory
    bool splitKeepsNear_ = false;    ///< particle_split: this frame kept its near sets and texels' near terms (far_handoff)
    bool splitHistory_ = false;      ///< particle_split: buf_.prevSlotOf and prevTexelLr hold last frame's
    Particles particles_;  ///< this frame's, rebased to origin_
    std::map<std::uint32_t, Particles> loaded_;  ///< --seeds: each frame's particles, loaded once
    nlohmann::json stats_;
    std::string timingsCsv_ = "config,pass,ms\n";
};

FrameFacts planningFacts(const Args& a) {
    FrameFacts facts;
    facts.lightingSkipped = a.skipLighting;
    return facts;
}

TwinRun::TwinRun(const Args& a, const Settings& settings)
    : a_(a), s_(settings), settingsToml_(settingsToToml(settings)), source_(settings), cameras_(settings.camera),
      W_(settings.camera.width), H_(settings.camera.height), runPlan_(planFrame(settings, planningFacts(a))),
      sampling_(!a.skipLighting && !estimatorInfo(settings.render.estimator).sums && !estimatorInfo(settings.render.estimator).resampling &&
                !estimatorInfo(settings.render.estimator).reuse),
      lightingPlan_(planLighting(settings.render, H_)),
      omm_(settings.geometry.alpha == AlphaMode::disc && settings.gpu.omm != OmmMode::off) {
    if (a.shadowRays != ShadowRays::trace) shade_ = Raygen::shadeTraverse;
    cudaDeviceProp prop{};
    CUDA_CHECK(cudaGetDeviceProperties(&prop, 0));
    device_ = prop.name;
    const GeometrySettings& geometry = settings.geometry;
    accelOptions_.layout = geometry.layout;
    accelOptions_.spheres = geometry.primitive == Primitive::sphere;
    accelOptions_.build = geometry.build;
    accelOptions_.rebuildFraction = geometry.rebuild_fraction;
    accelOptions_.pooled = !a.perBlas;
    accelOptions_.compact = a.compact;
    accelOptions_.streams = a.buildStreams;
    accelOptions_.hostThreads = a.buildThreads;
    accelOptions_.omm = omm_ ? settings.gpu.omm : OmmMode::off;
    accelOptions_.ommLevel = settings.gpu.omm_level;
    pipeline_ = std::make_unique<TwinPipeline>(a.programs, a.validation, omm_, geometry.layout, accelOptions_.spheres,
                                               blasBuildFlags(accelOptions_));
    CUDA_CHECK(cudaStreamCreate(&stream_));
    timer_ = std::make_unique<GpuTimer>(stream_);
    accel_ = std::make_unique<ParticleAccel>(pipeline_->context(), accelOptions_);

    const std::size_t pixels = std::size_t(W_) * H_;
    buf_.gbuffer.resize(pixels * sizeof(GBufferTexel));
    buf_.Lr.resize(pixels * sizeof(Vec3));
    buf_.counters.resize(sizeof(LaunchCounters));
    buf_.params.resize(sizeof(LaunchParams));
    if (sampling_) {
        buf_.Lr_stderr.resize(pixels * sizeof(Vec3));
        buf_.spp.resize(pixels * sizeof(float));
        buf_.rejectedSamples.resize(pixels * sizeof(std::uint32_t));
    }
    // The lighting grid (the CPU's Restir::render): the image at resolution_scale.
    const float scale = static_cast<float>(settings.restir.resolution_scale);
    gridW_ = runPlan_.upsample ? lightingGridExtent(W_, scale) : W_;
    gridH_ = runPlan_.upsample ? lightingGridExtent(H_, scale) : H_;
    const std::size_t gridPixels = std::size_t(gridW_) * gridH_;
    if (runPlan_.restir) {
        buf_.resA.resize(gridPixels * sizeof(StoredReservoir));
        buf_.resB.resize(gridPixels * sizeof(StoredReservoir));
        buf_.rejected.resize(gridPixels * sizeof(std::uint32_t));
        if (runPlan_.upsample) {
            buf_.gridGbuffer.resize(gridPixels * sizeof(GBufferTexel));
            buf_.gridLr.resize(gridPixels * sizeof(Vec3));
        }
    }
    stats_ = statsHeader(settings, settingsToml_);
    stats_.update({{"renderer", "accretion-optix"}, {"device", device_}, {"optix_device", pipeline_->deviceProperties()},
                   {"repeat", a.repeat}, {"allocation", a.perBlas ? "per_blas" : "pooled"}, {"compact", a.compact},
                   {"build_streams", a.buildStreams}, {"build_threads", a.buildThreads},
                   {"layout", std::string(enumName(geometry.layout))},
                   {"primitive", std::string(enumName(geometry.primitive))}, {"seeds", a.seeds}});
}

/// With --seeds every seed runs the same frames: their particles are loaded once.
Particles TwinRun::particlesOf(std::uint32_t frame) {
    if (a_.seeds == 1) return source_.frame(frame);
    auto it = loaded_.find(frame);
    if (it == loaded_.end()) it = loaded_.emplace(frame, source_.frame(frame)).first;
    return it->second;  // a copy: rebased by the caller
}

/// The frame's plan, with its particles loaded (rebased) where the plan
/// loads them; a static scene's stay from its first frame, as the CPU's do.
FramePlan TwinRun::planFrameAndLoad(std::uint32_t frame) {
    FrameFacts facts = planningFacts(a_);
    facts.geometryBuilt = built_;
    facts.historyAvailable = history_;
    if (runPlan_.loadsParticles(facts)) {  // the run's plan: this frame's is made once its particles are known
        particles_ = particlesOf(frame);
        for (Vec3& p : particles_.position) p -= origin_;
    }
    facts.emissive = emissive(particles_);
    return planFrame(s_, facts);
}

/// The particle arrays the programs read, with each billboard's frame.
void TwinRun::uploadParticles(const Particles& particles, const Camera& camera) {
    const std::size_t n = particles.size();
    std::vector<BillboardFrame> frames(n);
    std::vector<float> dmin2(n);
    const float dmin = static_cast<float>(s_.shading.dmin);
    for (std::size_t i = 0; i < n; ++i) {
        frames[i] = billboardFrame(s_.geometry.orientation, camera, particles.position[i], particles.velocity[i]);
        const float d = std::max(particles.radius[i], dmin);
        dmin2[i] = d * d;
    }
    buf_.position.upload(particles.position);
    buf_.emission.upload(particles.emission);
    buf_.albedo.upload(particles.albedo);
    buf_.radius.upload(particles.radius);
    if (runPlan_.particleTexels || runPlan_.particleSplit) morton_ = mortonFrame(particles.position.data(), n);
    buf_.dmin2.upload(dmin2);
    buf_.frames.upload(frames);
}

/// The SER hint of restir's shadow rays: each particle's BLAS (instances: its own).
void TwinRun::uploadClusterHint(const Particles& particles, bool recluster, bool first) {
    if (!runPlan_.restir || !(recluster || first)) return;
    const std::size_t n = particles.size();
    std::vector<std::uint32_t> of(n, 0);
    if (s_.geometry.layout == AccelLayout::instances)
        for (std::size_t i = 0; i < n; ++i) of[i] = static_cast<std::uint32_t>(i);
    for (std::size_t c = 0; c < clusters_.count(); ++c)
        for (std::uint32_t i : clusters_.members(c)) of[i] = static_cast<std::uint32_t>(c);
    buf_.particleCluster.upload(of);
}

LaunchParams TwinRun::launchParams(const FramePlan& plan, const Camera& camera, const Particles& particles,
                                   std::uint32_t frame, std::uint64_t seed) {
    const std::size_t n = particles.size();
    LaunchParams lp;
    lp.camera = camera;
    lp.model = s_.shading.model;
    lp.discAlpha = s_.geometry.alpha == AlphaMode::disc;
    lp.shadows = plan.shadowRays;
    lp.visibility = VisibilityOptions::from(s_.render);
    lp.omm = omm_;
    lp.layout = s_.geometry.layout;
    lp.spheres = accelOptions_.spheres;
    lp.particleCount = static_cast<std::uint32_t>(n);
    lp.position = buf_.position.as<Vec3>();
    lp.emission = buf_.emission.as<Vec3>();
    lp.albedo = buf_.albedo.as<Vec3>();
    lp.radius = buf_.radius.as<float>();
    lp.dmin2 = buf_.dmin2.as<float>();
    lp.frames = buf_.frames.as<BillboardFrame>();
    lp.gbuffer = buf_.gbuffer.as<GBufferTexel>();
    lp.Lr = buf_.Lr.as<Vec3>();
    lp.lights = {static_cast<std::uint32_t>(n), n ? 1.0f / float(n) : 0.0f, lp.position, lp.emission, lp.albedo, lp.dmin2};
    if (plan.sampler == LightSamplerKind::power) {  // buildLightSampler's alias table, as the CPU samples it
        const AliasTable table = buildPowerTable(particles);
        buf_.aliasProb.upload(table.probabilities());
        buf_.aliasAlias.upload(table.aliases());
        buf_.aliasPmf.upload(table.pmfs());
        lp.source.power = true;
        lp.source.table = {buf_.aliasProb.as<float>(), buf_.aliasAlias.as<std::uint32_t>(), buf_.aliasPmf.as<float>()};
    }
    if (plan.sampler == LightSamplerKind::tree) {  // buildLightSampler's light tree: the CPU's nodes, the same descent
        const LightTree tree(particles, s_.shading);
        buf_.treeNodes.upload(tree.nodes());
        lp.tree = tree.view();
        lp.tree.nodes = buf_.treeNodes.as<LightTreeNode>();
        if (plan.particleSplit) {  // the near search starts below the root, on each light's path
            buf_.treePaths.upload(tree.paths());
            lp.split.lightPath = buf_.treePaths.as<std::uint64_t>();
        }
    }
    lp.source.count = lp.lights.count;
    lp.source.uniformPdf = lp.lights.uniformPdf;
    if (sampling_) {
        SamplingParams& sp = lp.sampling;
        sp.frame = frame;
        sp.seed = seed;
        sp.plan = lightingPlan_;
        sp.maxSamples = s_.render.max_samples;
        sp.targetStderr = s_.render.target_stderr;
        sp.discardNonFinite = s_.render.nonfinite == NonFinitePolicy::discard;
        sp.Lr_stderr = buf_.Lr_stderr.as<Vec3>();
        sp.spp = buf_.spp.as<float>();
        sp.rejected = buf_.rejectedSamples.as<std::uint32_t>();
    }
    if (plan.voxelCache) lp.voxel.params = voxelParams(s_, voxelPlacement_, origin_, camera, frame, seed);
    if (plan.particleSplit) lp.split.params = psplit::splitParams(s_, 0, frame, seed);  // visible: after the gather
    if (plan.restir) {
        RestirParams& rp = lp.restir;
        const RestirSettings& rs = s_.restir;
        rp.reuse = restir::reuseParams(s_, frame, seed, gridW_, gridH_, plan.upsample ? float(gridW_) / float(W_) : 1.0f);
        rp.gbuffer = plan.upsample ? buf_.gridGbuffer.as<GBufferTexel>() : lp.gbuffer;
        rp.Lr = plan.upsample ? buf_.gridLr.as<Vec3>() : lp.Lr;
        rp.temporal = plan.temporal;
        rp.bias = rs.bias_correction;
        rp.visibilityReuse = rs.visibility_reuse;
        rp.discardNonFinite = s_.render.nonfinite == NonFinitePolicy::discard;
        rp.reorder = a_.shadowRays == ShadowRays::reorder;
        rp.serHintBits = s_.gpu.ser_hint_bits;
        rp.rejected = buf_.rejected.as<std::uint32_t>();
        rp.particleCluster = buf_.particleCluster.as<std::uint32_t>();
        rp.prevLights = {prevCount_, prevCount_ ? 1.0f / float(prevCount_) : 0.0f, buf_.prevPosition.as<Vec3>(),
                         buf_.prevEmission.as<Vec3>(), buf_.prevAlbedo.as<Vec3>(), buf_.prevDmin2.as<float>()};
        rp.prevGbuffer = buf_.prevGbuffer.as<GBufferTexel>();
        rp.prevReservoirs = buf_.prevReservoirs.as<StoredReservoir>();
        rp.prevCamera = prevCamera_;
        rp.prevSlotOf = buf_.prevSlotOf.as<std::uint32_t>();
        rp.prevSlotCount = plan.temporal ? prevCount_ : 0;
        rp.prevTexelLr = buf_.prevTexelLr.as<Vec3>();
    }
    return lp;
}

/// gatherParticleTexels (particle_restir and particle_split): the visible
/// particles in Morton order into buf_.gatherSortedIds and their slots into
/// buf_.slotOf, their side x side x layers texels into buf_.gridGbuffer,
/// gridW_ x gridH_ (kTexelRowWidth a row), where `points` puts them.
/// Returns how many are visible.
std::uint32_t TwinRun::gatherTexels(const LaunchParams& lp, std::uint32_t side, std::uint32_t layers, const TexelPointRule& points) {
    const std::uint32_t n = lp.particleCount;
    buf_.gatherFlags.reserve(n);
    for (DeviceBuffer* b : {&buf_.gatherIds, &buf_.gatherSortedIds, &buf_.slotOf}) b->reserve(n * sizeof(std::uint32_t));
    for (DeviceBuffer* b : {&buf_.gatherKeys, &buf_.gatherSortedKeys}) b->reserve(n * sizeof(std::uint64_t));
    buf_.gatherCount.reserve(sizeof(std::uint32_t));
    buf_.gatherTemp.reserve(gatherTempBytes(n));
    const GatherArrays arrays{buf_.gatherFlags.as<std::uint8_t>(), buf_.gatherIds.as<std::uint32_t>(),
                              buf_.gatherSortedIds.as<std::uint32_t>(), buf_.gatherCount.as<std::uint32_t>(),
                              buf_.slotOf.as<std::uint32_t>(), buf_.gatherKeys.as<std::uint64_t>(),
                              buf_.gatherSortedKeys.as<std::uint64_t>(), buf_.gatherTemp.as<void>(), buf_.gatherTemp.bytes()};
    const std::uint32_t visible = findVisibleParticles(lp, morton_, arrays, stream_);
    const std::size_t texels = std::size_t(visible) * side * side * layers;
    gridW_ = kTexelRowWidth;
    gridH_ = std::max(1u, std::uint32_t((texels + kTexelRowWidth - 1) / kTexelRowWidth));  // one row of misses when none is seen
    const std::size_t grid = std::size_t(gridW_) * gridH_;
    buf_.gridGbuffer.reserve(grid * sizeof(GBufferTexel));
    writeParticleTexels(lp, arrays.sortedIds, visible, side, layers, points, grid, buf_.gridGbuffer.as<GBufferTexel>(), stream_);
    return visible;
}

/// A launch of a thread per ray of each item, `threads` of them: thread L
/// = idx.y x width + idx.x in one row (--ray-launch texels or linear) or in
/// rows of `rowWidth` (rows: a 2D launch).
void TwinRun::launchRays(Raygen r, std::size_t threads, unsigned rowWidth) {
    if (a_.rayLaunch != RayLaunch::rows) pipeline_->launch(r, buf_.params.address(), sizeof(LaunchParams), unsigned(threads), 1, stream_);
    else pipeline_->launch(r, buf_.params.address(), sizeof(LaunchParams), rowWidth, unsigned(threads / rowWidth), stream_);
}

/// particle_split's passes (the CPU's ParticleSplit::render):
/// gatherParticleTexels, findNearLights (a kernel per visible particle),
/// shadeSplitTexels (a raygen of a thread per ray of each texel, then a
/// kernel that sums each texel's rays in order) and
/// shadeParticlePixels (a kernel per pixel). Run again, they compute the
/// same texels: last frame's are read from buf_.prevTexelLr, this frame's
/// written to buf_.gridLr.
void TwinRun::runParticleSplit(LaunchParams& lp) {
    SplitLaunch& sl = lp.split;
    GpuTimer& timer = *timer_;
    {
        GpuScope t(timer, Pass::gatherParticleTexels);
        sl.params.visible = gatherTexels(lp, s_.particle_split.texels, 1, psplit::texelPoints(s_, sl.params.frame, sl.params.seed));
    }
    const std::size_t grid = std::size_t(gridW_) * gridH_, visible = sl.params.visible;
    splitVisible_ = visible;
    splitKeepsNear_ = sl.params.keepsNearTerms();
    buf_.splitNear.reserve(std::max<std::size_t>(1, visible * sl.params.nearCount) * sizeof(std::uint32_t));
    buf_.splitNearFound.reserve(std::max<std::size_t>(1, visible) * sizeof(std::uint32_t));
    buf_.splitNearRadius2.reserve(std::max<std::size_t>(1, visible) * sizeof(float));
    // Every texel's near and far rays; far_new's extra rays of the texels without history after them.
    const std::uint32_t rays = psplit::raysPerTexel(sl.params), extra = psplit::extraNewRays(sl.params);
    if (double(grid) * (rays + extra) > double(1u << 30))
        throw InputError(fmt::format("particle_split: {} texels x {} rays, more than an OptiX launch holds (2^30)", grid, rays + extra));
    if (extra && a_.rayLaunch == RayLaunch::rows)
        throw InputError("particle_split.far_new: its extra rays are launched in one row (--ray-launch texels or linear, not rows)");
    buf_.splitRays.reserve(std::max<std::size_t>(1, grid * (rays + extra)) * sizeof(psplit::SplitRay));
    SplitSelectArrays select;
    if (extra) {
        buf_.splitNewFlags.reserve(grid);
        buf_.splitNewIds.reserve(grid * sizeof(std::uint32_t));
        buf_.splitNewTexels.reserve(grid * sizeof(std::uint32_t));
        buf_.splitNewCount.reserve(sizeof(std::uint32_t));
        select.tempBytes = splitSelectTempBytes(grid);
        buf_.splitSelectTemp.reserve(std::max<std::size_t>(1, select.tempBytes));
        select.flags = buf_.splitNewFlags.as<std::uint8_t>();
        select.ids = buf_.splitNewIds.as<std::uint32_t>();
        select.count = buf_.splitNewCount.as<std::uint32_t>();
        select.temp = buf_.splitSelectTemp.as<void>();
        sl.newTexels = buf_.splitNewTexels.as<std::uint32_t>();
    }
    buf_.gridLr.reserve(grid * sizeof(Vec3));
    buf_.rejected.reserve(std::max(grid, std::size_t(W_) * H_) * sizeof(std::uint32_t));
    CUDA_CHECK(cudaMemsetAsync(buf_.rejected.as<void>(), 0, grid * sizeof(std::uint32_t), stream_));
    sl.particleOf = buf_.gatherSortedIds.as<std::uint32_t>();
    sl.slotOf = buf_.slotOf.as<std::uint32_t>();
    sl.texels = buf_.gridGbuffer.as<GBufferTexel>();
    sl.near = buf_.splitNear.as<std::uint32_t>();
    sl.nearFound = buf_.splitNearFound.as<std::uint32_t>();
    sl.nearRadius2 = buf_.splitNearRadius2.as<float>();
    sl.rays = buf_.splitRays.as<psplit::SplitRay>();
    sl.rayStride = grid;
    sl.texelMajor = a_.rayLaunch == RayLaunch::texels;
    sl.texelLr = buf_.gridLr.as<Vec3>();
    sl.rejected = buf_.rejected.as<std::uint32_t>();
    sl.prevSlotOf = buf_.prevSlotOf.as<std::uint32_t>();
    sl.prevSlotCount = splitHistory_ && sl.params.history > 0.0f ? prevCount_ : 0;
    sl.prevTexelLr = buf_.prevTexelLr.as<Vec3>();
    if (sl.params.history > 0.0f && sl.params.historyOfFar) {
        buf_.splitFar.reserve(grid * sizeof(Vec3));
        sl.texelFar = buf_.splitFar.as<Vec3>();
        sl.prevTexelFar = buf_.prevSplitFar.as<Vec3>();
    }
    if (splitKeepsNear_) {
        buf_.splitTexelNear.reserve(std::max<std::size_t>(1, grid * sl.params.nearCount) * sizeof(Vec3));
        sl.texelNear = buf_.splitTexelNear.as<Vec3>();
        sl.prevTexelNear = buf_.prevSplitTexelNear.as<Vec3>();
        sl.prevNear = buf_.prevSplitNear.as<std::uint32_t>();
        sl.prevNearFound = buf_.prevSplitNearFound.as<std::uint32_t>();
    }
    if (sl.params.history > 0.0f && sl.params.historyMean) {
        buf_.splitAge.reserve(grid * sizeof(std::uint32_t));
        sl.texelAge = buf_.splitAge.as<std::uint32_t>();
        sl.prevTexelAge = buf_.prevSplitAge.as<std::uint32_t>();
    }
    {
        GpuScope t(timer, Pass::findNearLights);
        findNearLights(lp, stream_);
    }
    {
        GpuScope t(timer, Pass::shadeSplitTexels);
        CUDA_CHECK(cudaMemcpyAsync(buf_.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream_));
        // Thread L traces splitRayOfThread(L) (--ray-launch texels, the
        // default: the CPU's counting order), or ray L / grid of texel L %
        // grid (linear, rows). OptiX maps a 2D launch (rows) onto warps and
        // blocks its own way: on the H100 (no RT cores) its warps stalled at
        // barriers, up to 2.7x slower (run.sh ray_launch, split_order).
        // far_new: the texels without history selected first, their extra rays launched after every texel's own.
        const std::size_t fresh = extra ? selectNewSplitTexels(lp, grid, select, stream_) : 0;
        if (grid * rays + fresh * extra > 0) launchRays(Raygen::shadeSplitTexels, grid * rays + fresh * extra, unsigned(grid));
        sumSplitTexels(lp, grid, stream_);
    }
    {
        GpuScope t(timer, Pass::shadeParticlePixels);
        interpolateSplitPixels(lp, stream_);
    }
    CUDA_CHECK(cudaGetLastError());
}

/// particle_split.history: this frame's slots and texels become the next
/// frame's history (by particle id).
void TwinRun::keepSplitHistory(std::size_t n) {
    if (s_.particle_split.history <= 0.0) return;
    copyDevice(buf_.prevSlotOf, buf_.slotOf, n * sizeof(std::uint32_t), stream_);
    copyDevice(buf_.prevTexelLr, buf_.gridLr, std::size_t(gridW_) * gridH_ * sizeof(Vec3), stream_);
    if (s_.particle_split.history_of == HistoryOf::far)
        copyDevice(buf_.prevSplitFar, buf_.splitFar, std::size_t(gridW_) * gridH_ * sizeof(Vec3), stream_);
    if (s_.particle_split.history_start == HistoryStart::mean)
        copyDevice(buf_.prevSplitAge, buf_.splitAge, std::size_t(gridW_) * gridH_ * sizeof(std::uint32_t), stream_);
    if (splitKeepsNear_) {
        const std::size_t k = s_.particle_split.near;
        copyDevice(buf_.prevSplitNear, buf_.splitNear, std::max<std::size_t>(1, splitVisible_ * k) * sizeof(std::uint32_t), stream_);
        copyDevice(buf_.prevSplitNearFound, buf_.splitNearFound, std::max<std::size_t>(1, splitVisible_) * sizeof(std::uint32_t), stream_);
        copyDevice(buf_.prevSplitTexelNear, buf_.splitTexelNear, std::max<std::size_t>(1, std::size_t(gridW_) * gridH_ * k) * sizeof(Vec3), stream_);
    }
    CUDA_CHECK(cudaStreamSynchronize(stream_));
    prevCount_ = static_cast<std::uint32_t>(n);
    splitHistory_ = true;
}

/// The restir passes of a frame after the G-buffer, as the plan has them
/// (the CPU's Restir::render): generateCandidates, temporalResampling,
/// spatialResampling x plan.spatialIterations, traceShadowRays, and with
/// plan.upsample the reduced G-buffer first and upsampleLighting last.
/// Returns the final reservoirs (the next frame's history).
StoredReservoir* TwinRun::runRestir(const FramePlan& plan, LaunchParams& lp) {
    RestirParams& rp = lp.restir;
    GpuTimer& timer = *timer_;
    if (plan.particleTexels) {  // the lighting grid: the visible particles' texels, kTexelRowWidth a row
        GpuScope t(timer, Pass::gatherParticleTexels);
        const std::uint32_t visible = gatherTexels(lp, s_.restir.texels, s_.restir.texel_rays, TexelPointRule{});
        const std::size_t grid = std::size_t(gridW_) * gridH_;
        buf_.resA.reserve(grid * sizeof(StoredReservoir));
        buf_.resB.reserve(grid * sizeof(StoredReservoir));
        buf_.gridLr.reserve(grid * sizeof(Vec3));
        buf_.rejected.reserve(std::max(grid, std::size_t(W_) * H_) * sizeof(std::uint32_t));
        rp.reuse.width = gridW_;
        rp.reuse.height = gridH_;
        rp.reuse.visible = visible;
        rp.gbuffer = buf_.gridGbuffer.as<GBufferTexel>();
        rp.Lr = buf_.gridLr.as<Vec3>();
        rp.rejected = buf_.rejected.as<std::uint32_t>();
        rp.slotOf = buf_.slotOf.as<std::uint32_t>();
    }
    const std::size_t pixels = std::max(std::size_t(rp.reuse.width) * rp.reuse.height,
                                        plan.particleTexels ? std::size_t(W_) * H_ : std::size_t(0));
    if (plan.upsample) {
        GpuScope t(timer, Pass::upsampleLighting, "reduceGBuffer");
        reduceGBuffer(lp, buf_.gridGbuffer.as<GBufferTexel>(), stream_);
    }
    StoredReservoir* a = buf_.resA.as<StoredReservoir>();
    StoredReservoir* b = buf_.resB.as<StoredReservoir>();
    CUDA_CHECK(cudaMemsetAsync(buf_.rejected.as<void>(), 0, pixels * sizeof(std::uint32_t), stream_));
    {
        GpuScope t(timer, Pass::generateCandidates);
        rp.in = nullptr;
        rp.out = a;
        generateCandidates(lp, stream_);
    }
    if (rp.temporal) {
        GpuScope t(timer, Pass::temporalResampling);
        rp.in = a;
        rp.out = b;
        if (plan.particleTexels) temporalResamplingById(lp, stream_);
        else temporalResampling(lp, stream_);
        std::swap(a, b);
    }
    const std::uint32_t iterations = plan.spatialIterations;
    for (std::uint32_t it = 0; it < iterations; ++it) {  // each iteration timed apart, as the CPU counts it
        GpuScope t(timer, plan.particleTexels ? Pass::resampleWorldNeighbours : Pass::spatialResampling, {}, it + 1);
        rp.in = a;
        rp.out = b;
        if (plan.particleTexels) resampleWorldNeighbours(lp, it, stream_);
        else spatialResampling(lp, it, stream_);
        std::swap(a, b);
    }
    if (plan.traceShadowRays) {
        GpuScope t(timer, Pass::traceShadowRays);
        rp.in = nullptr;
        rp.out = a;
        CUDA_CHECK(cudaMemcpyAsync(buf_.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream_));
        pipeline_->launch(shade_, buf_.params.address(), sizeof lp, rp.reuse.width, rp.reuse.height, stream_);
        if (plan.texelHistory) accumulateTexelLr(lp, stream_);
    }
    if (plan.particleTexels) {  // the pixels from their particles' texels
        GpuScope t(timer, plan.resamplePixels ? Pass::resampleParticlePixels : Pass::shadeParticlePixels);
        rp.in = a;
        if (!plan.resamplePixels) {
            interpolatePixels(lp, stream_);
        } else {
            const BiasCorrection chain = rp.bias;  // no canonical sample at the pixel: basic for pairwise (the CPU's rule)
            if (rp.bias == BiasCorrection::pairwise) rp.bias = BiasCorrection::basic;
            CUDA_CHECK(cudaMemcpyAsync(buf_.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream_));
            pipeline_->launch(Raygen::resampleParticlePixels, buf_.params.address(), sizeof lp, W_, H_, stream_);
            rp.bias = chain;
        }
    }
    if (plan.upsample) {
        GpuScope t(timer, Pass::upsampleLighting);
        upsampleLighting(lp, stream_);
    }
    CUDA_CHECK(cudaGetLastError());
    return a;
}

/// voxel_cache's grid: kept while it holds the particles, else placed again
/// and its cells emptied (the CPU's VoxelCache::render).
void TwinRun::placeVoxels(const Particles& particles) {
    if (voxelPlacement_.holds(particles, origin_)) return;
    voxelPlacement_ = placeVoxelGrid(particles, origin_, s_.voxel.cells);
    const std::size_t cells = voxelPlacement_.cells();
    if (double(cells) * s_.voxel.rays > double(1u << 30))
        throw InputError(fmt::format("voxel.cells = {} with voxel.rays = {}: {} rays a frame, more than an OptiX launch holds (2^30)",
                                     s_.voxel.cells, s_.voxel.rays, double(cells) * s_.voxel.rays));
    for (DeviceBuffer& b : buf_.voxelCells) {
        b.reserve(cells * sizeof(voxel::VoxelCell));
        CUDA_CHECK(cudaMemsetAsync(b.as<void>(), 0, cells * sizeof(voxel::VoxelCell), stream_));
    }
    buf_.voxelOccupied.reserve(cells);
    buf_.voxelRays.reserve(cells * s_.voxel.rays * sizeof(voxel::CellRay));
    voxelLast_ = 0;
}

/// voxel_cache's passes (the CPU's VoxelCache::render): updateVoxelCache
/// (the reached cells marked; a raygen over their rays, one a thread: a
/// cell's rays run at once, not one after another, as a thread per cell
/// would, which a few thousand cells leave latency-bound; then a kernel per
/// cell summing them, reading last frame's cells and writing this frame's)
/// and shadeVoxelPixels (a kernel per pixel). Run again, they compute the
/// same cells: last frame's stay.
void TwinRun::runVoxelCache(LaunchParams& lp) {
    VoxelLaunch& v = lp.voxel;
    const voxel::VoxelGrid& grid = v.params.grid;
    voxel::VoxelCell* next = buf_.voxelCells[voxelLast_ ^ 1u].as<voxel::VoxelCell>();
    {
        GpuScope t(*timer_, Pass::updateVoxelCache);
        markVoxelCells(lp, buf_.voxelOccupied.as<std::uint8_t>(), grid.count(), stream_);
        v.occupied = buf_.voxelOccupied.as<std::uint8_t>();
        v.read = buf_.voxelCells[voxelLast_].as<voxel::VoxelCell>();
        v.write = next;
        v.rays = buf_.voxelRays.as<voxel::CellRay>();
        CUDA_CHECK(cudaMemcpyAsync(buf_.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream_));
        launchRays(Raygen::updateVoxelCache, std::size_t(grid.count()) * v.params.rays, grid.nx * v.params.rays);
        sumVoxelRays(lp, stream_);
    }
    {
        GpuScope t(*timer_, Pass::shadeVoxelPixels);
        v.read = next;
        shadeVoxelPixels(lp, stream_);
    }
    CUDA_CHECK(cudaGetLastError());
}

/// The frame's passes: one counting run (its atomics would be timed too),
/// then `repeat` timed runs when repeat > 1. A rebuild runs in every run;
/// so does a refit (of positions that have not moved since the first run:
/// the same boxes again), so that its time is a median as every other's.
/// The first build of a persistent BVH runs once, and so does a partial
/// rebuild (each moves its round-robin cursor: the stale clusters change).
StepTimes TwinRun::runPasses(const FramePlan& plan, LaunchParams& lp, const Clusters& clusters, bool recluster,
                             LaunchCounters& counters, StoredReservoir*& finalReservoirs) {
    StepTimes ms, counted;
    const DeviceParticles dp{lp.particleCount, lp.position, lp.radius, lp.frames};
    const bool instances = s_.geometry.layout == AccelLayout::instances;
    const std::size_t pixels = std::size_t(W_) * H_;
    const unsigned runs = a_.repeat > 1 ? a_.repeat + 1 : 1;
    const bool buildOnce = runPlan_.updateInPlace && (recluster || s_.geometry.build == BuildPolicy::partial);
    for (unsigned r = 0; r < runs; ++r) {
        lp.counters = r == 0 ? buf_.counters.as<LaunchCounters>() : nullptr;
        if (plan.buildClusters && (r == 0 || !buildOnce))
            accel_->build(recluster || instances ? &clusters : nullptr, dp, stream_, *timer_);
        lp.tlas = accel_->tlas();
        lp.clusterParticle = accel_->clusterParticle();
        lp.clusterOffset = accel_->clusterOffset();
        CUDA_CHECK(cudaMemcpyAsync(buf_.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream_));
        CUDA_CHECK(cudaMemsetAsync(buf_.counters.as<void>(), 0, sizeof(LaunchCounters), stream_));
        {
            GpuScope s(*timer_, Pass::traceGBuffer);
            pipeline_->launch(Raygen::gbuffer, buf_.params.address(), sizeof lp, W_, H_, stream_);
        }
        if (plan.restir) {
            finalReservoirs = runRestir(plan, lp);
        } else if (plan.voxelCache) {
            runVoxelCache(lp);
        } else if (plan.particleSplit) {
            runParticleSplit(lp);
        } else if (plan.lighting) {
            GpuScope s(*timer_, Pass::estimateLighting);
            pipeline_->launch(sampling_ ? Raygen::sample : Raygen::exact, buf_.params.address(), sizeof lp, W_, H_, stream_);
        } else {  // nothing lights the frame: Lr = 0, as the CPU's lightFrame
            CUDA_CHECK(cudaMemsetAsync(buf_.Lr.as<void>(), 0, pixels * sizeof(Vec3), stream_));
            if (sampling_) {
                CUDA_CHECK(cudaMemsetAsync(buf_.Lr_stderr.as<void>(), 0, pixels * sizeof(Vec3), stream_));
                CUDA_CHECK(cudaMemsetAsync(buf_.spp.as<void>(), 0, pixels * sizeof(float), stream_));
                CUDA_CHECK(cudaMemsetAsync(buf_.rejectedSamples.as<void>(), 0, pixels * sizeof(std::uint32_t), stream_));
            }
        }
        for (const auto& [step, t] : timer_->read()) (r == 0 ? counted : ms)[step].push_back(t);
        if (r == 0) counters = buf_.counters.download<LaunchCounters>(1)[0];
    }
    for (auto& [step, t] : counted)
        if (!ms.count(step)) ms[step] = t;  // single run, or a step only the first run has
    return ms;
}

/// This frame becomes the previous one of restir's temporal reuse.
void TwinRun::keepHistory(const Camera& camera, std::size_t n, const StoredReservoir* finalReservoirs) {
    if (!runPlan_.keepHistory) return;
    if (!finalReservoirs) {  // an unlit frame leaves no reservoirs to reuse
        history_ = false;
        return;
    }
    const std::size_t gridPixels = std::size_t(gridW_) * gridH_;
    if (runPlan_.particleTexels) {  // the slots by id, and the texels' Lr for texel_history
        copyDevice(buf_.prevSlotOf, buf_.slotOf, n * sizeof(std::uint32_t), stream_);
        if (s_.restir.texel_history > 0.0) copyDevice(buf_.prevTexelLr, buf_.gridLr, gridPixels * sizeof(Vec3), stream_);
    }
    copyDevice(buf_.prevPosition, buf_.position, n * sizeof(Vec3), stream_);
    copyDevice(buf_.prevEmission, buf_.emission, n * sizeof(Vec3), stream_);
    copyDevice(buf_.prevAlbedo, buf_.albedo, n * sizeof(Vec3), stream_);
    copyDevice(buf_.prevDmin2, buf_.dmin2, n * sizeof(float), stream_);
    copyDevice(buf_.prevGbuffer, runPlan_.upsample || runPlan_.particleTexels ? buf_.gridGbuffer : buf_.gbuffer,
               gridPixels * sizeof(GBufferTexel), stream_);
    buf_.prevReservoirs.reserve(gridPixels * sizeof(StoredReservoir));
    CUDA_CHECK(cudaMemcpyAsync(buf_.prevReservoirs.as<void>(), finalReservoirs, gridPixels * sizeof(StoredReservoir),
                               cudaMemcpyDeviceToDevice, stream_));
    CUDA_CHECK(cudaStreamSynchronize(stream_));
    prevCamera_ = camera;
    prevCount_ = static_cast<std::uint32_t>(n);
    history_ = true;
}

/// The frame's layers, composed by composeImage's loop (composeLayers).
GpuFrame TwinRun::composeFrame(const FramePlan& plan, const Particles& particles, std::uint32_t frame,
                               const CameraPose& pose, std::size_t& hits, std::size_t& nonFinite) const {
    const std::size_t pixels = std::size_t(W_) * H_;
    const std::vector<GBufferTexel> gb = buf_.gbuffer.download<GBufferTexel>(pixels);
    GpuFrame out;
    out.width = W_;
    out.height = H_;
    out.frame = frame;
    out.camera = pose;
    out.Lr = buf_.Lr.download<Vec3>(pixels);
    if (sampling_) {
        out.Lr_stderr = buf_.Lr_stderr.download<Vec3>(pixels);
        out.spp = buf_.spp.download<float>(pixels);
        const std::vector<std::uint32_t> rejected = buf_.rejectedSamples.download<std::uint32_t>(pixels);
        out.rejected.assign(rejected.begin(), rejected.end());
    }
    const ComposeTotals t = composeLayers(gb, particles.emission, s_.shading,
                                          {out.L, out.Le, out.depth, out.normal, out.particle, out.Lr, out.Lr_stderr, out.rejected, out.spp});
    hits = t.hits;
    nonFinite = t.nonFinite;
    if (a_.lrOnly) {
        out.L.clear();
        out.Le.clear();
        out.normal.clear();
        out.depth.clear();
        out.particle.clear();
        out.Lr_stderr.clear();
        out.spp.clear();
        out.rejected.clear();
    }
    return out;
}

void TwinRun::renderFrame(std::uint32_t frame, std::uint64_t seed) {
    const auto wall0 = std::chrono::steady_clock::now();
    const CameraPose pose = cameras_.pose(frame);
    const Camera world = Camera::fromPose(pose, W_, H_);
    if (!built_ || !runPlan_.updateInPlace) origin_ = world.position;
    const Camera camera = world.rebased(origin_);
    const FramePlan plan = planFrameAndLoad(frame);
    const Particles& particles = particles_;
    const std::size_t n = particles.size();
    const bool instances = s_.geometry.layout == AccelLayout::instances;
    const bool recluster = plan.buildClusters && !instances && (!built_ || !runPlan_.updateInPlace);
    const Clusters clusters = recluster ? clusterParticles(particles.position, s_.geometry.cluster_size) : Clusters{};
    if (plan.loadParticles) uploadParticles(particles, camera);
    if (recluster) clusters_ = clusters;
    uploadClusterHint(particles, recluster, frame == s_.render.frame_start);

    if (plan.voxelCache) placeVoxels(particles);
    LaunchParams lp = launchParams(plan, camera, particles, frame, seed);
    LaunchCounters counters{};
    StoredReservoir* finalReservoirs = nullptr;
    const StepTimes ms = runPasses(plan, lp, clusters, recluster, counters, finalReservoirs);
    built_ = true;
    if (plan.voxelCache) voxelLast_ ^= 1u;  // this frame's cells are the next one's last
    if (plan.particleSplit) keepSplitHistory(n);
    keepHistory(camera, n, finalReservoirs);

    std::size_t hits = 0, nonFinite = 0;
    GpuFrame out = composeFrame(plan, particles, frame, pose, hits, nonFinite);
    nlohmann::json timing;
    std::map<std::string, double> calibrated;  // by the pass runs of `accretion cost` ("spatialResampling[2]")
    for (const auto& [step, v] : ms) {
        timing[step] = {{"median_ms", median(v)}, {"ms", v}};
        calibrated[timer_->passOf(step).label()] += median(v);
    }
    timingsCsv_ = "config,pass,ms\n";  // the last frame's
    if (!a_.config.empty())
        for (const auto& [p, t] : calibrated) timingsCsv_ += fmt::format("{},{},{:.6f}\n", csvCell(a_.config), p, t);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    out.metadata = frameMetadata(s_, settingsToml_, frame, seed, "", wall);
    out.metadata.insert({{"lighting", a_.skipLighting ? "skipped" : std::string(enumName(s_.render.estimator))},
                         {"shadow_rays", std::string(enumName(a_.shadowRays))}, {"ray_launch", std::string(enumName(a_.rayLaunch))},
                         {"renderer", "accretion-optix"}, {"device", device_},
                         {"tonemap", std::string(enumName(s_.render.tonemap))}});
    std::filesystem::path file = expandPattern(s_.render.output, s_.sceneName, frame);
    file = file.parent_path() /
           (file.stem().string() + (a_.seeds > 1 ? fmt::format(".seed{}", seed) : std::string()) + ".gpuframe");
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    writeGpuFrame(file, out);
    const AccelStats& as = accel_->stats();
    std::vector<std::string> passes;
    for (const Pass pass : plan.passes()) passes.emplace_back(passName(pass));
    stats_["frames"].push_back({{"frame", frame}, {"output", file.string()}, {"passes", passes}, {"particles", n},
                                {"hit_pixels", hits}, {"blases", as.blases}, {"instances", as.instances},
                                {"primitives", as.primitives}, {"largest_blas_primitives", as.largestBlas},
                                {"rebuilt_blases", as.rebuiltBlases}, {"refitted", as.refitted}, {"partial", as.partial},
                                {"blas_bytes", as.blasBytes}, {"blas_memory_bytes", as.poolBytes},
                                {"scratch_bytes", as.tempBytes}, {"blas_enqueue_ms", as.blasEnqueueMs}, {"tlas_bytes", as.tlasBytes},
                                {"input_bytes", as.inputBytes}, {"accel_total_bytes", as.totalBytes()},
                                {"primary_rays", std::size_t(W_) * H_}, {"shadow_rays", counters.rays},
                                {"any_hits", counters.anyHits}, {"compose_nonfinite", nonFinite},
                                {"shadow_occluded", counters.occluded}, {"light_terms", counters.lightTerms},
                                {"shadow_retests", counters.retests}, {"seed", seed}, {"omm_bytes", as.ommBytes},
                                {"gpu_ms", timing}, {"wall_s", wall}});
    if (!a_.quiet) {
        std::string line;
        for (const auto& [step, v] : ms) line += fmt::format(" {} {:.3f}", step, median(v));
        fmt::print(stderr, "frame {}: {} ({} BLAS, {} instances; ms:{})\n", frame, file.string(), as.blases, as.instances, line);
    }
}

void TwinRun::writeRunOutputs() const {
    const std::filesystem::path first = expandPattern(s_.render.output, s_.sceneName, s_.render.frame_start);
    writeJson((first.parent_path() / first.stem()).string() + ".gpu_stats.json", stats_);
    if (!a_.timings.empty()) writeFileAtomic(a_.timings, timingsCsv_);
}

int run(const Args& a) {
    std::vector<FlagSetting> flags = frameFlags(a.frames);
    if (!a.output.empty())
        flags.push_back({"render.output", "-o " + a.output, [o = a.output](Settings& s) { s.render.output = o; }});
    const Settings settings = loadScene(a.scene, a.defines, flags);
    requireSupported(settings, !a.skipLighting);
    TwinRun twin(a, settings);
    const std::uint32_t first = settings.render.frame_start, frameCount = settings.render.frames;
    // --seeds: the frames again per seed (render.seed + k), each run from scratch.
    for (std::uint64_t step = 0; step < std::uint64_t(a.seeds) * frameCount; ++step) {
        const std::uint32_t frame = first + std::uint32_t(step % frameCount);
        if (frame == first) twin.restart();
        twin.renderFrame(frame, settings.render.seed + step / frameCount);
    }
    twin.writeRunOutputs();
    return 0;
}
}  // namespace
}  // namespace accretion::twin

int main(int argc, char** argv) {
    accretion::twin::Args a;
    CLI::App app{"accretion-optix: the OptiX twin of the GPU pipeline (exact, uniform, power and restir lighting; frames as .gpuframe)"};
    app.add_option("scene", a.scene, "Scene file (TOML)")->required()->check(CLI::ExistingFile);
    app.add_option("-D,--define", a.defines, "Override a setting: section.key=value");
    app.add_option("--frames", a.frames, "Frames A:B (half-open) = render.frame_start, render.frames");
    app.add_option("-o,--output", a.output, "Output pattern ({scene}, {frame}; the extension becomes .gpuframe) = render.output");
    app.add_option("--repeat", a.repeat,
                   "Timed runs of the frame's passes for the median GPU time (with more than 1, an untimed "
                   "counting run comes first)")->check(CLI::Range(1, 1000));
    app.add_option("--timings", a.timings,
                   "Write the last frame's median GPU ms per pass as calibrate's timings CSV (config,pass,ms)");
    app.add_option("--seeds", a.seeds,
                   "Run the frames once per seed render.seed + k, k < N (outputs get .seed<S> before the extension)")
        ->check(CLI::Range(1, 100000));
    app.add_option("--config", a.config, "Configuration name of the timings rows");
    app.add_option("--programs", a.programs, "The OptiX-IR of programs.cu");
    accretion::twin::addEnumOption(app, "--shadow-rays", a.shadowRays,
                   "restir's traceShadowRays: trace (optixTrace, pipeline), traverse (optixTraverse + hit object, "
                   "inline-like) or reorder (traverse after optixReorder by the SER key: gpu.ser_hint_bits of the light's BLAS)");
    accretion::twin::addEnumOption(app, "--ray-launch", a.rayLaunch,
           "The launches of a thread per ray of each item (updateVoxelCache's cells, shadeSplitTexels' texels), in one "
           "row: texels (a cell's rays side by side; a texel's near rays, then its far ones: the CPU's counting order; the "
           "default), linear (the same cells; a split ray of every texel, then the next); or rows (a 2D launch of the "
           "linear order, as OptiX tiles it)");
    app.add_option("--build-streams", a.buildStreams, "CUDA streams the BLAS builds are spread over (round robin)")
        ->check(CLI::Range(1, 64));
    app.add_option("--build-threads", a.buildThreads,
                   "Host threads issuing the BLAS builds, each on its own stream with its own scratch")
        ->check(CLI::Range(1, 64));
    app.add_flag("--per-blas", a.perBlas, "One cudaMalloc per BLAS instead of one 256-B-aligned pool");
    app.add_flag("--compact", a.compact, "Compact every BLAS after its build");
    app.add_flag("--lr-only", a.lrOnly, "Frames hold Lr alone (for `accretion bias --gpu-frames`; import-gpu refuses them)");
    app.add_flag("--skip-lighting", a.skipLighting, "Time the geometry passes only (Lr = 0 in the frame)");
    app.add_flag("--validation", a.validation, "OptiX validation mode");
    app.add_flag("-q,--quiet", a.quiet, "No progress on stderr");
    CLI11_PARSE(app, argc, argv);
    try {
        return accretion::twin::run(a);
    } catch (const accretion::InputError& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 1;
    }
}
