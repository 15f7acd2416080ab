// accretion-optix: the OptiX twin of the GPU pipeline. It reads
// the scene files, particle buffers and settings `accretion render` reads,
// runs the pipeline on the GPU (per-frame cluster BLAS builds, TLAS,
// G-buffer raygen, lighting) and writes per frame a .gpuframe (the layers
// render writes; `accretion import-gpu` makes render's EXR of it), the
// per-pass GPU times (CUDA events, median of --repeat launches) as
// calibrate's timings CSV, and a stats JSON.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/median.h"
#include "accretion/core/parse.h"
#include "accretion/core/version.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/geometry/clustering.h"
#include "accretion/io/gpu_frame_file.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/accumulation.h"
#include "accretion/render/compose_pixel.h"
#include "accretion/render/upsample_pixel.h"
#include "accretion/scene/scene_parser.h"
#include "launch_params.h"
#include "optix_pipeline.h"
#include "particle_accel.h"
#include "restir_kernels.h"

#ifndef ACCRETION_TWIN_PROGRAMS
#define ACCRETION_TWIN_PROGRAMS "programs.optixir"
#endif

namespace accretion::twin {
namespace {

struct Args {
    std::string scene;
    std::vector<std::string> defines;
    std::string frames, output, timings, config, programs = ACCRETION_TWIN_PROGRAMS;
    std::string shadowRays = "trace";
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
    if (g.layout == AccelLayout::aabbs && s.gpu.omm != OmmMode::off && g.alpha == AlphaMode::disc)
        refuse("gpu.omm with geometry.layout = \"aabbs\" (micromaps are for triangles)");
    if (g.layout == AccelLayout::instances && g.build != BuildPolicy::rebuild && g.build != BuildPolicy::refit)
        refuse(fmt::format("geometry.build = \"{}\" with geometry.layout = \"instances\" (rebuild or refit the TLAS)",
                           enumName(g.build)));
    const EstimatorKind e = s.render.estimator;
    if (lighting && e != EstimatorKind::exact && e != EstimatorKind::uniform && e != EstimatorKind::power &&
        e != EstimatorKind::restir)
        refuse(fmt::format("render.estimator = \"{}\"", enumName(e)));
    if (lighting && e == EstimatorKind::restir) {
        const RestirSettings& r = s.restir;
        if (s.render.source == LightSource::tree) refuse("render.source = \"tree\"");
        if (s.render.source == LightSource::tiles) refuse("render.source = \"tiles\"");
        if (s.render.source == LightSource::regir) refuse("render.source = \"regir\"");
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
    DeviceBuffer gridGbuffer, gridLr;  // restir.resolution_scale < 1: the lighting grid
    DeviceBuffer prevPosition, prevEmission, prevAlbedo, prevDmin2, prevGbuffer, prevReservoirs;
    DeviceBuffer aliasProb, aliasAlias, aliasPmf;  // power: the alias table
    DeviceBuffer Lr_stderr, spp, rejectedSamples;  // uniform / power
};

void copyDevice(DeviceBuffer& to, const DeviceBuffer& from, std::size_t bytes, cudaStream_t stream) {
    to.reserve(bytes);
    CUDA_CHECK(cudaMemcpyAsync(to.as<void>(), from.as<void>(), bytes, cudaMemcpyDeviceToDevice, stream));
}

/// The restir passes of a frame after the G-buffer (the CPU's runPasses):
/// generateCandidates, temporalResampling (with a history),
/// spatialResampling x iterations, traceShadowRays. Returns the final
/// reservoirs (the next frame's history).
StoredReservoir* runRestir(LaunchParams& lp, FrameBuffers& buf, const Settings& s, Raygen shade, const TwinPipeline& pipeline,
                           cudaStream_t stream, GpuTimer& timer) {
    RestirParams& rp = lp.restir;
    const std::size_t pixels = std::size_t(rp.width) * rp.height;
    const bool upsample = rp.width != s.camera.width || rp.height != s.camera.height;
    if (upsample) {
        GpuScope t(timer, Pass::upsampleLighting, "reduceGBuffer");
        reduceGBuffer(lp, buf.gridGbuffer.as<GBufferTexel>(), stream);
    }
    StoredReservoir* a = buf.resA.as<StoredReservoir>();
    StoredReservoir* b = buf.resB.as<StoredReservoir>();
    CUDA_CHECK(cudaMemsetAsync(buf.rejected.as<void>(), 0, pixels * sizeof(std::uint32_t), stream));
    {
        GpuScope t(timer, Pass::generateCandidates);
        rp.in = nullptr;
        rp.out = a;
        generateCandidates(lp, stream);
    }
    if (rp.temporal) {
        GpuScope t(timer, Pass::temporalResampling);
        rp.in = a;
        rp.out = b;
        temporalResampling(lp, stream);
        std::swap(a, b);
    }
    const std::uint32_t iterations = s.restir.spatial_neighbours > 0 ? s.restir.spatial_iterations : 0;
    if (iterations > 0) {
        GpuScope t(timer, Pass::spatialResampling);
        for (std::uint32_t it = 0; it < iterations; ++it) {
            rp.in = a;
            rp.out = b;
            spatialResampling(lp, it, stream);
            std::swap(a, b);
        }
    }
    {
        GpuScope t(timer, Pass::traceShadowRays);
        rp.in = nullptr;
        rp.out = a;
        CUDA_CHECK(cudaMemcpyAsync(buf.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream));
        pipeline.launch(shade, buf.params.address(), sizeof lp, rp.width, rp.height, stream);
    }
    if (upsample) {
        GpuScope t(timer, Pass::upsampleLighting);
        upsampleLighting(lp, stream);
    }
    CUDA_CHECK(cudaGetLastError());
    return a;
}

int run(const Args& a) {
    std::vector<FlagSetting> flags = frameFlags(a.frames);
    if (!a.output.empty())
        flags.push_back({"render.output", "-o " + a.output, [o = a.output](Settings& s) { s.render.output = o; }});
    const Settings settings = loadScene(a.scene, a.defines, flags);
    requireSupported(settings, !a.skipLighting);
    const std::string settingsToml = settingsToToml(settings);
    const ParticleSource source(settings);
    const CameraTrack cameras(settings.camera);
    const std::uint32_t W = settings.camera.width, H = settings.camera.height;
    const std::size_t pixels = std::size_t(W) * H;

    cudaDeviceProp prop{};
    CUDA_CHECK(cudaGetDeviceProperties(&prop, 0));
    const std::string device = prop.name;
    const bool omm = settings.geometry.alpha == AlphaMode::disc && settings.gpu.omm != OmmMode::off;
    const GeometrySettings& geometry = settings.geometry;
    AccelOptions accelOptions;
    accelOptions.layout = geometry.layout;
    accelOptions.spheres = geometry.primitive == Primitive::sphere;
    accelOptions.build = geometry.build;
    accelOptions.rebuildFraction = geometry.rebuild_fraction;
    accelOptions.pooled = !a.perBlas;
    accelOptions.compact = a.compact;
    accelOptions.streams = a.buildStreams;
    accelOptions.hostThreads = a.buildThreads;
    accelOptions.omm = omm ? settings.gpu.omm : OmmMode::off;
    accelOptions.ommLevel = settings.gpu.omm_level;
    TwinPipeline pipeline(a.programs, a.validation, omm, geometry.layout, accelOptions.spheres, blasBuildFlags(accelOptions));
    cudaStream_t stream;
    CUDA_CHECK(cudaStreamCreate(&stream));
    GpuTimer timer(stream);
    ParticleAccel accel(pipeline.context(), accelOptions);
    FrameBuffers buf;
    buf.gbuffer.resize(pixels * sizeof(GBufferTexel));
    buf.Lr.resize(pixels * sizeof(Vec3));
    buf.counters.resize(sizeof(LaunchCounters));
    buf.params.resize(sizeof(LaunchParams));

    const bool restir = !a.skipLighting && settings.render.estimator == EstimatorKind::restir;
    const bool sampling = !a.skipLighting && (settings.render.estimator == EstimatorKind::uniform ||
                                              settings.render.estimator == EstimatorKind::power);
    const bool powerSource = !a.skipLighting && (settings.render.estimator == EstimatorKind::power ||
                                                 (restir && settings.render.source == LightSource::power));
    const LightingPlan plan = planLighting(settings.render, H);
    if (sampling) {
        buf.Lr_stderr.resize(pixels * sizeof(Vec3));
        buf.spp.resize(pixels * sizeof(float));
        buf.rejectedSamples.resize(pixels * sizeof(std::uint32_t));
    }
    const bool keepHistory = restir && settings.restir.temporal && settings.render.frames > 1;
    Raygen shade = Raygen::shade;
    if (a.shadowRays == "traverse" || a.shadowRays == "reorder") shade = Raygen::shadeTraverse;
    else if (a.shadowRays != "trace")
        throw InputError(fmt::format("command line --shadow-rays {}: expected trace, traverse or reorder", a.shadowRays));
    // The lighting grid (the CPU's Restir::render): the image at resolution_scale.
    const float scale = static_cast<float>(settings.restir.resolution_scale);
    const bool upsample = restir && scale < 1.0f;
    const std::uint32_t gridW = upsample ? lightingGridExtent(W, scale) : W;
    const std::uint32_t gridH = upsample ? lightingGridExtent(H, scale) : H;
    const std::size_t gridPixels = std::size_t(gridW) * gridH;
    if (restir) {
        buf.resA.resize(gridPixels * sizeof(StoredReservoir));
        buf.resB.resize(gridPixels * sizeof(StoredReservoir));
        buf.rejected.resize(gridPixels * sizeof(std::uint32_t));
        if (upsample) {
            buf.gridGbuffer.resize(gridPixels * sizeof(GBufferTexel));
            buf.gridLr.resize(gridPixels * sizeof(Vec3));
        }
    }
    bool history = false;
    Camera prevCamera{};
    std::uint32_t prevCount = 0;
    Clusters current;
    const BuildPolicy policy = settings.geometry.build;
    const bool persistent = policy == BuildPolicy::refit || policy == BuildPolicy::partial;
    const bool statelessBuild = !persistent;
    Vec3 origin(0.0f);
    bool built = false;
    std::string timingsCsv = "config,pass,ms\n";
    nlohmann::json stats = {{"version", std::string(version())}, {"renderer", "accretion-optix"}, {"device", device},
                            {"optix_device", pipeline.deviceProperties()}, {"scene", settings.scenePath}, {"repeat", a.repeat}, {"allocation", a.perBlas ? "per_blas" : "pooled"},
                            {"compact", a.compact}, {"build_streams", a.buildStreams}, {"build_threads", a.buildThreads},
                            {"layout", std::string(enumName(settings.geometry.layout))},
                            {"primitive", std::string(enumName(settings.geometry.primitive))}, {"seeds", a.seeds}, {"frames", nlohmann::json::array()}};
    const std::uint32_t first = settings.render.frame_start, frameCount = settings.render.frames;
    // With --seeds every seed runs the same frames: their particles are loaded once.
    std::map<std::uint32_t, Particles> loaded;
    auto loadParticles = [&](std::uint32_t f) {
        if (a.seeds == 1) return source.frame(f);
        auto it = loaded.find(f);
        if (it == loaded.end()) it = loaded.emplace(f, source.frame(f)).first;
        return it->second;  // a copy: rebased below
    };
    // --seeds: the frames again per seed (render.seed + k), each run from scratch.
    for (std::uint64_t step = 0; step < std::uint64_t(a.seeds) * frameCount; ++step) {
        const std::uint32_t frame = first + std::uint32_t(step % frameCount);
        const std::uint64_t seed = settings.render.seed + step / frameCount;
        if (frame == first) {
            history = built = false;
            prevCount = 0;
        }
        const auto wall0 = std::chrono::steady_clock::now();
        const CameraPose pose = cameras.pose(frame);
        const Camera world = Camera::fromPose(pose, W, H);
        if (!built || !persistent) origin = world.position;
        const Camera camera = world.rebased(origin);
        Particles particles = loadParticles(frame);
        for (Vec3& p : particles.position) p -= origin;
        const std::size_t n = particles.size();
        std::vector<BillboardFrame> frames(n);
        std::vector<float> dmin2(n);
        const float dmin = static_cast<float>(settings.shading.dmin);
        for (std::size_t i = 0; i < n; ++i) {
            frames[i] = billboardFrame(settings.geometry.orientation, camera, particles.position[i], particles.velocity[i]);
            const float d = std::max(particles.radius[i], dmin);
            dmin2[i] = d * d;
        }
        buf.position.upload(particles.position);
        buf.emission.upload(particles.emission);
        buf.albedo.upload(particles.albedo);
        buf.radius.upload(particles.radius);
        buf.dmin2.upload(dmin2);
        buf.frames.upload(frames);
        const bool instances = geometry.layout == AccelLayout::instances;
        const bool recluster = !instances && (!built || !persistent);
        const Clusters clusters = recluster ? clusterParticles(particles.position, geometry.cluster_size) : Clusters{};
        if (recluster) current = clusters;
        if (restir && (recluster || frame == first)) {  // the SER hint: each particle's BLAS (instances: its own)
            std::vector<std::uint32_t> of(n, 0);
            if (instances)
                for (std::size_t i = 0; i < n; ++i) of[i] = static_cast<std::uint32_t>(i);
            for (std::size_t c = 0; c < current.count(); ++c)
                for (std::uint32_t i : current.members(c)) of[i] = static_cast<std::uint32_t>(c);
            buf.particleCluster.upload(of);
        }

        LaunchParams lp;
        lp.camera = camera;
        lp.model = settings.shading.model;
        lp.discAlpha = settings.geometry.alpha == AlphaMode::disc;
        lp.shadows = settings.shading.visibility;
        lp.visibility = VisibilityOptions::from(settings.render);
        lp.omm = omm;
        lp.layout = geometry.layout;
        lp.spheres = accelOptions.spheres;
        lp.particleCount = static_cast<std::uint32_t>(n);
        lp.position = buf.position.as<Vec3>();
        lp.emission = buf.emission.as<Vec3>();
        lp.albedo = buf.albedo.as<Vec3>();
        lp.radius = buf.radius.as<float>();
        lp.dmin2 = buf.dmin2.as<float>();
        lp.frames = buf.frames.as<BillboardFrame>();
        lp.gbuffer = buf.gbuffer.as<GBufferTexel>();
        lp.Lr = buf.Lr.as<Vec3>();
        lp.lights = {static_cast<std::uint32_t>(n), n ? 1.0f / float(n) : 0.0f, lp.position, lp.emission, lp.albedo, lp.dmin2};
        if (powerSource) {  // buildPowerTable's arrays, as the CPU samples them
            const AliasTable table = buildPowerTable(particles);
            buf.aliasProb.upload(table.probabilities());
            buf.aliasAlias.upload(table.aliases());
            buf.aliasPmf.upload(table.pmfs());
            lp.source.power = true;
            lp.source.table = {buf.aliasProb.as<float>(), buf.aliasAlias.as<std::uint32_t>(), buf.aliasPmf.as<float>()};
        }
        lp.source.count = lp.lights.count;
        lp.source.uniformPdf = lp.lights.uniformPdf;
        if (sampling) {
            SamplingParams& sp = lp.sampling;
            sp.frame = frame;
            sp.seed = seed;
            sp.plan = plan;
            sp.maxSamples = settings.render.max_samples;
            sp.targetStderr = settings.render.target_stderr;
            sp.discardNonFinite = settings.render.nonfinite == NonFinitePolicy::discard;
            sp.Lr_stderr = buf.Lr_stderr.as<Vec3>();
            sp.spp = buf.spp.as<float>();
            sp.rejected = buf.rejectedSamples.as<std::uint32_t>();
        }
        if (restir) {
            RestirParams& rp = lp.restir;
            const RestirSettings& rs = settings.restir;
            rp.frame = frame;
            rp.seed = seed;
            rp.candidates = settings.render.candidates;
            rp.width = gridW;
            rp.height = gridH;
            rp.scale = upsample ? float(gridW) / float(W) : 1.0f;
            rp.gbuffer = upsample ? buf.gridGbuffer.as<GBufferTexel>() : lp.gbuffer;
            rp.Lr = upsample ? buf.gridLr.as<Vec3>() : lp.Lr;
            rp.temporal = keepHistory && history;
            rp.neighbours = rs.spatial_neighbours;
            rp.radius = std::max(1.0f, float(rs.spatial_radius) * rp.scale);
            rp.normalThreshold = float(rs.normal_threshold);
            rp.depthThreshold = float(rs.depth_threshold);
            rp.mCap = rs.m_cap;
            rp.bias = rs.bias_correction;
            rp.visibilityReuse = rs.visibility_reuse;
            rp.discardNonFinite = settings.render.nonfinite == NonFinitePolicy::discard;
            rp.reorder = a.shadowRays == "reorder";
            rp.serHintBits = settings.gpu.ser_hint_bits;
            rp.rejected = buf.rejected.as<std::uint32_t>();
            rp.particleCluster = buf.particleCluster.as<std::uint32_t>();
            rp.prevLights = {prevCount, prevCount ? 1.0f / float(prevCount) : 0.0f, buf.prevPosition.as<Vec3>(),
                             buf.prevEmission.as<Vec3>(), buf.prevAlbedo.as<Vec3>(), buf.prevDmin2.as<float>()};
            rp.prevGbuffer = buf.prevGbuffer.as<GBufferTexel>();
            rp.prevReservoirs = buf.prevReservoirs.as<StoredReservoir>();
            rp.prevCamera = prevCamera;
        }

        // The frame's passes: one counting run (its atomics would be timed too),
        // then `repeat` timed runs when repeat > 1. A refit or partial build
        // changes state: it runs once per frame, in the first run, whose time
        // it keeps.
        std::map<std::string, std::vector<double>> ms, counted;
        LaunchCounters counters{};
        StoredReservoir* finalReservoirs = nullptr;
        const DeviceParticles dp{lp.particleCount, lp.position, lp.radius, lp.frames};
        const unsigned runs = a.repeat > 1 ? a.repeat + 1 : 1;
        for (unsigned r = 0; r < runs; ++r) {
            lp.counters = r == 0 ? buf.counters.as<LaunchCounters>() : nullptr;
            if (r == 0 || statelessBuild) accel.build(recluster || instances ? &clusters : nullptr, dp, stream, timer);
            lp.tlas = accel.tlas();
            lp.clusterParticle = accel.clusterParticle();
            lp.clusterOffset = accel.clusterOffset();
            CUDA_CHECK(cudaMemcpyAsync(buf.params.as<void>(), &lp, sizeof lp, cudaMemcpyHostToDevice, stream));
            CUDA_CHECK(cudaMemsetAsync(buf.counters.as<void>(), 0, sizeof(LaunchCounters), stream));
            {
                GpuScope s(timer, Pass::traceGBuffer);
                pipeline.launch(Raygen::gbuffer, buf.params.address(), sizeof lp, W, H, stream);
            }
            if (restir) {
                finalReservoirs = runRestir(lp, buf, settings, shade, pipeline, stream, timer);
            } else if (!a.skipLighting) {
                GpuScope s(timer, Pass::estimateLighting);
                pipeline.launch(sampling ? Raygen::sample : Raygen::exact, buf.params.address(), sizeof lp, W, H, stream);
            } else {
                CUDA_CHECK(cudaMemsetAsync(buf.Lr.as<void>(), 0, pixels * sizeof(Vec3), stream));
            }
            for (const auto& [pass, t] : timer.read()) (r == 0 ? counted : ms)[pass].push_back(t);
            if (r == 0) counters = buf.counters.download<LaunchCounters>(1)[0];
        }
        for (auto& [pass, t] : counted)
            if (!ms.count(pass)) ms[pass] = t;  // single run, or a pass only the first run has
        built = true;
        if (keepHistory) {  // this frame becomes the previous one
            copyDevice(buf.prevPosition, buf.position, n * sizeof(Vec3), stream);
            copyDevice(buf.prevEmission, buf.emission, n * sizeof(Vec3), stream);
            copyDevice(buf.prevAlbedo, buf.albedo, n * sizeof(Vec3), stream);
            copyDevice(buf.prevDmin2, buf.dmin2, n * sizeof(float), stream);
            copyDevice(buf.prevGbuffer, upsample ? buf.gridGbuffer : buf.gbuffer, gridPixels * sizeof(GBufferTexel), stream);
            buf.prevReservoirs.reserve(gridPixels * sizeof(StoredReservoir));
            CUDA_CHECK(cudaMemcpyAsync(buf.prevReservoirs.as<void>(), finalReservoirs, gridPixels * sizeof(StoredReservoir),
                                       cudaMemcpyDeviceToDevice, stream));
            CUDA_CHECK(cudaStreamSynchronize(stream));
            prevCamera = camera;
            prevCount = static_cast<std::uint32_t>(n);
            history = true;
        }

        // Compose (L = Le + Lr, the background on a miss) by composeImage's rule.
        const std::vector<GBufferTexel> gb = buf.gbuffer.download<GBufferTexel>(pixels);
        GpuFrame out;
        out.width = W;
        out.height = H;
        out.frame = frame;
        out.camera = pose;
        out.Lr = buf.Lr.download<Vec3>(pixels);
        out.L.resize(pixels);
        out.Le.assign(pixels, Vec3(0.0f));
        out.normal.assign(pixels, Vec3(0.0f));
        out.depth.resize(pixels);
        out.particle.resize(pixels);
        if (sampling) {
            out.Lr_stderr = buf.Lr_stderr.download<Vec3>(pixels);
            out.spp = buf.spp.download<float>(pixels);
            const std::vector<std::uint32_t> rejected = buf.rejectedSamples.download<std::uint32_t>(pixels);
            out.rejected.assign(rejected.begin(), rejected.end());
        }
        const float se = static_cast<float>(settings.shading.self_emission);
        std::size_t hits = 0, nonFinite = 0;
        for (std::size_t px = 0; px < pixels; ++px) {
            const GBufferTexel& g = gb[px];
            out.particle[px] = g.particle;
            if (!g.hit()) {
                out.L[px] = settings.shading.background;
                out.depth[px] = std::numeric_limits<float>::infinity();
                out.Lr[px] = Vec3(0.0f);
                continue;
            }
            ++hits;
            if (!composeHit(se, particles.emission[g.particle], out.Lr[px], out.Le[px], out.L[px])) {
                ++nonFinite;
                if (sampling) {  // as composeImage
                    out.Lr_stderr[px] = Vec3(0.0f);
                    out.rejected[px] += 1.0f;
                }
            }
            out.depth[px] = g.depth;
            out.normal[px] = g.normal;
        }
        nlohmann::json timing;
        std::map<std::string, double> calibrated;  // by the pass names of `accretion cost`
        for (const auto& [pass, v] : ms) {
            timing[pass] = {{"median_ms", median(v)}, {"ms", v}};
            calibrated[std::string(passName(timer.passOf(pass)))] += median(v);
        }
        timingsCsv = "config,pass,ms\n";  // the last frame's
        if (!a.config.empty())
            for (const auto& [pass, t] : calibrated) timingsCsv += fmt::format("{},{},{:.6f}\n", a.config, pass, t);
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
        out.metadata = {{"lighting", a.skipLighting ? "skipped" : std::string(enumName(settings.render.estimator))},
                        {"shadow_rays", a.shadowRays}, {"version", std::string(version())}, {"scene", settings.scenePath},
                        {"frame", std::to_string(frame)}, {"estimator", std::string(enumName(settings.render.estimator))},
                        {"samples", std::to_string(settings.render.samples)}, {"seed", std::to_string(seed)},
                        {"shard", ""}, {"render_time_s", fmt::format("{:.6f}", wall)}, {"settings", settingsToml},
                        {"renderer", "accretion-optix"}, {"device", device},
                        {"tonemap", std::string(enumName(settings.render.tonemap))}};
        std::filesystem::path file = expandPattern(settings.render.output, settings.sceneName, frame);
        file = file.parent_path() /
               (file.stem().string() + (a.seeds > 1 ? fmt::format(".seed{}", seed) : std::string()) + ".gpuframe");
        if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
        if (a.lrOnly) {
            out.L.clear();
            out.Le.clear();
            out.normal.clear();
            out.depth.clear();
            out.particle.clear();
            out.Lr_stderr.clear();
            out.spp.clear();
            out.rejected.clear();
        }
        writeGpuFrame(file, out);
        const AccelStats& as = accel.stats();
        stats["frames"].push_back({{"frame", frame}, {"output", file.string()}, {"particles", n}, {"hit_pixels", hits},
                                   {"blases", as.blases}, {"instances", as.instances}, {"primitives", as.primitives},
                                   {"largest_blas_primitives", as.largestBlas},
                                   {"rebuilt_blases", as.rebuiltBlases}, {"refitted", as.refitted}, {"partial", as.partial},
                                   {"blas_bytes", as.blasBytes}, {"blas_memory_bytes", as.poolBytes},
                                   {"scratch_bytes", as.tempBytes}, {"blas_enqueue_ms", as.blasEnqueueMs}, {"tlas_bytes", as.tlasBytes},
                                   {"input_bytes", as.inputBytes}, {"accel_total_bytes", as.totalBytes()},
                                   {"primary_rays", pixels}, {"shadow_rays", counters.rays}, {"any_hits", counters.anyHits},
                                   {"compose_nonfinite", nonFinite},
                                   {"shadow_occluded", counters.occluded}, {"light_terms", counters.lightTerms},
                                   {"shadow_retests", counters.retests}, {"seed", seed}, {"omm_bytes", as.ommBytes},
                                   {"gpu_ms", timing}, {"wall_s", wall}});
        if (!a.quiet) {
            std::string line;
            for (const auto& [pass, v] : ms) line += fmt::format(" {} {:.3f}", pass, median(v));
            fmt::print(stderr, "frame {}: {} ({} BLAS, {} instances; ms:{})\n", frame, file.string(), as.blases, as.instances, line);
        }
    }
    const std::filesystem::path first_ = expandPattern(settings.render.output, settings.sceneName, first);
    const std::string stem = (first_.parent_path() / first_.stem()).string();
    writeFileAtomic(stem + ".gpu_stats.json", stats.dump(2));
    if (!a.timings.empty()) writeFileAtomic(a.timings, timingsCsv);
    CUDA_CHECK(cudaStreamDestroy(stream));
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
    app.add_option("--shadow-rays", a.shadowRays,
                   "restir's traceShadowRays: trace (optixTrace, pipeline), traverse (optixTraverse + hit object, "
                   "inline-like) or reorder (traverse after optixReorder by the SER key: gpu.ser_hint_bits of the light's BLAS)");
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
