#include "accretion/render/frame_plan.h"

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/math.h"
#include "accretion/lighting/reservoir_codec.h"

namespace accretion {
namespace {

/// restir with restir.crop_margin: render.crop and the margin around it,
/// its corners on the 8-pixel grid of the traced tiles, within the image;
/// else the whole image.
PixelWindow restirWindow(const Settings& s) {
    const PixelWindow whole = PixelWindow::whole(s.camera.width, s.camera.height);
    if (!estimatorInfo(s.render.estimator).reuse || s.restir.crop_margin < 0.0 || s.render.crop.size() != 4) return whole;
    const PixelWindow crop = PixelWindow::of(s);
    const auto m = static_cast<std::uint32_t>(s.restir.crop_margin);
    auto down = [&](std::uint32_t v) { return (v > m ? v - m : 0u) / 8u * 8u; };
    auto up = [&](std::uint32_t v, std::uint32_t end) { return std::min<std::uint64_t>(end, (std::uint64_t(v) + m + 7u) / 8u * 8u); };
    return {down(crop.x0), std::uint32_t(up(crop.x1, whole.x1)), down(crop.y0), std::uint32_t(up(crop.y1, whole.y1))};
}

/// The run-wide part of the plan: the same for every frame.
void planRun(const Settings& s, FramePlan& plan) {
    const bool staticCamera = s.camera.path == CameraPath::static_pose ||
                              (s.camera.path == CameraPath::orbit && s.camera.orbit_speed == 0.0);
    const bool restir = estimatorInfo(s.render.estimator).restirPasses();
    plan.staticGeometry = staticParticles(s.particles) && staticCamera;
    plan.updateInPlace = s.geometry.build == BuildPolicy::refit || s.geometry.build == BuildPolicy::partial;
    plan.alphaFilter = s.geometry.primitive == Primitive::billboard && s.geometry.alpha == AlphaMode::disc;
    plan.keepHistory = restir && s.restir.temporal && s.render.frames > 1;
    // A static scene's one BVH is also last frame's.
    plan.previousBvh = plan.keepHistory && s.shading.visibility && !plan.staticGeometry && needsPreviousBvh(s);
    plan.counting = s.gpu.counters;
    ACC_CHECK(!restir || !cropRendersAlone(s));  // reuse reads the neighbours: the whole frame
    plan.traced = cropRendersAlone(s) ? PixelWindow::of(s) : PixelWindow::whole(s.camera.width, s.camera.height);
    plan.frameWindow = restirWindow(s);
    if (!plan.frameWindow.isWhole(s.camera.width, s.camera.height))
        plan.traced = PixelWindow::whole(plan.frameWindow.width(), plan.frameWindow.height());
}

/// This frame's passes.
void planPasses(const Settings& s, const FrameFacts& facts, FramePlan& plan) {
    const EstimatorInfo& est = estimatorInfo(s.render.estimator);
    plan.loadParticles = plan.buildClusters = plan.loadsParticles(facts);
    plan.lighting = !facts.lightingSkipped && facts.emissive && glm::length(s.shading.albedo) > 0.0f;
    plan.shadowRays = plan.lighting && s.shading.visibility;
    if (plan.lighting) plan.sampler = samplerFor(s.render);  // tiles and the ReGIR grid are drawn from the power table
    plan.chooseNearLights = plan.lighting && est.nearField && s.render.near_lights == 0;
    const LightSourceInfo& source = sourceInfo(s.render.source);
    plan.restir = plan.lighting && est.restirPasses();
    plan.voxelCache = plan.lighting && est.passes == LightingPasses::voxelCache;
    plan.particleSplit = plan.lighting && est.passes == LightingPasses::particleSplit;
    plan.presampleTiles = plan.restir && source.presampled;
    plan.presampleRegir = plan.restir && source.regirGrid;
    plan.temporal = plan.restir && plan.keepHistory && facts.historyAvailable;
    plan.spatialIterations = plan.restir && s.restir.spatial_neighbours > 0 ? s.restir.spatial_iterations : 0;
    plan.upsample = plan.restir && float(s.restir.resolution_scale) < 1.0f;
    plan.particleTexels = plan.restir && s.render.estimator == EstimatorKind::particle_restir;
    plan.resamplePixels = plan.particleTexels && s.restir.pixel_shading == PixelShading::resample;
    plan.traceShadowRays = plan.restir && (!plan.particleTexels || !plan.resamplePixels ||
                                           (s.restir.visibility_reuse && plan.shadowRays));
    plan.texelHistory = plan.particleTexels && plan.temporal && s.restir.pixel_shading == PixelShading::interpolate &&
                        s.restir.texel_history > 0.0;
}

/// The plan as lines, with what each step does or why it is skipped.
void describe(const Settings& s, const FrameFacts& facts, FramePlan& plan) {
    const EstimatorKind est = s.render.estimator;
    const bool restir = estimatorInfo(est).restirPasses();
    const bool manyFrames = s.render.frames > 1;
    auto step = [&](Pass pass, std::string why) { plan.steps.push_back({pass, {}, true, std::move(why)}); };
    auto work = [&](std::string name, bool runs, std::string why) {
        plan.steps.push_back({std::nullopt, std::move(name), runs, std::move(why)});
    };
    const std::string once = "static particles and camera: built at the first frame";
    step(Pass::loadParticles,
         !plan.loadParticles ? once : plan.staticGeometry && manyFrames ? "once: the particles do not move" : "every frame");
    step(Pass::buildClusters,
         !plan.buildClusters ? once
         : plan.staticGeometry ? (manyFrames ? "once for all frames: static particles and camera" : "one frame")
                               : fmt::format("every frame ({})", enumName(s.geometry.build)));
    work("alpha filter callbacks", plan.alphaFilter,
         plan.alphaFilter ? (s.gpu.omm == OmmMode::off ? "disc alpha: any-hit on every candidate"
                                                       : fmt::format("disc alpha with {} OMM level {}", enumName(s.gpu.omm), s.gpu.omm_level))
                          : "no alpha test (opaque quads or spheres)");
    work("previous-frame BVH", plan.previousBvh,
         plan.previousBvh ? "basic_visibility tests history samples against last frame's geometry"
                          : "not needed (no basic_visibility with history and visibility reuse)");
    const bool dark = !plan.lighting;
    const std::string noLight = facts.lightingSkipped ? "no lighting passes: skipped by the command (geometry timed alone)"
                                : !facts.emissive ? "no lighting passes: no particle emits"
                                                  : "no lighting passes: albedo 0";
    step(Pass::buildLightSampler,
         plan.sampler == LightSamplerKind::tree    ? "light tree"
         : plan.sampler == LightSamplerKind::power ? "alias table over light power"
         : dark ? noLight : fmt::format("{} samples lights uniformly", enumName(est)));
    if (estimatorInfo(est).nearField)
        step(Pass::chooseNearLights, plan.chooseNearLights ? "the pilot picks render.near_lights from V(k) x (k + rho S) at 64 pixels across"
                                     : dark ? noLight : fmt::format("render.near_lights = {}", s.render.near_lights));
    const PixelWindow& fw = plan.frameWindow;
    step(Pass::traceGBuffer,
         !fw.isWhole(s.camera.width, s.camera.height)
             ? fmt::format("one primary ray per pixel of render.crop and its restir.crop_margin: the {}x{} window at ({}, {})",
                           fw.width(), fw.height(), fw.x0, fw.y0)
         : plan.traced.isWhole(s.camera.width, s.camera.height)
             ? std::string("one primary ray per pixel")
             : fmt::format("one primary ray per pixel of render.crop's {}x{} window", plan.traced.width(), plan.traced.height()));
    step(Pass::estimateLighting,
         dark ? noLight : restir ? "the restir passes below"
         : estimatorInfo(est).passes == LightingPasses::voxelCache    ? "the voxel cache's passes below"
         : estimatorInfo(est).passes == LightingPasses::particleSplit ? "particle_split's passes below"
                                                                      : std::string(enumName(est)));
    if (restir) {
        const RestirSettings& r = s.restir;
        step(Pass::presampleLightTiles,
             plan.presampleTiles ? fmt::format("{} tiles x {} lights by power", r.tile_count, r.tile_size)
             : dark ? noLight : fmt::format("source {}: no light tiles", enumName(s.render.source)));
        step(Pass::presampleRegirGrid,
             plan.presampleRegir ? fmt::format("{}^3 cells x {} reservoirs of {} tile candidates", r.regir_cells,
                                               r.regir_lights_per_cell, r.regir_build_samples)
             : dark ? noLight : fmt::format("source {}: no ReGIR grid", enumName(s.render.source)));
        const bool particles = est == EstimatorKind::particle_restir;
        const std::string texels = fmt::format("{0}x{0} texels x {1} reservoirs", r.texels, r.texel_rays);
        if (particles)
            step(Pass::gatherParticleTexels, dark ? noLight : fmt::format("the visible particles in Morton order, {} each", texels));
        step(Pass::generateCandidates,
             dark ? noLight : fmt::format("{} candidates from {}{}", s.render.candidates, enumName(s.render.source),
                                          particles ? " per particle texel" : ""));
        step(Pass::temporalResampling,
             plan.temporal ? (particles ? "the same texel of the same particle (by id)" : "reprojection through particle motion")
             : dark ? noLight : !s.restir.temporal ? "temporal off: no history buffers or motion"
             : !manyFrames ? "one frame: no history buffers or motion" : "first frame: no history yet");
        const std::string neighbours =
            plan.spatialIterations ? fmt::format("{} neighbours x {}", s.restir.spatial_neighbours, s.restir.spatial_iterations)
                                   : (dark ? noLight : "no neighbours");
        if (particles)
            step(Pass::resampleWorldNeighbours,
                 plan.spatialIterations
                     ? fmt::format("{} among the {} visible particles either side in world (Morton) order", neighbours, r.world_neighbours)
                     : neighbours);
        else
            step(Pass::spatialResampling, neighbours);
        step(Pass::traceShadowRays,
             dark ? noLight
             : !plan.traceShadowRays ? "pixel_shading resample: each pixel traces its own (resampleParticlePixels), the texels none"
             : plan.shadowRays ? (particles ? fmt::format("one shadow ray per particle texel and reservoir{}",
                                                          plan.texelHistory ? fmt::format(", Lr averaged with last frame's (h = {})", r.texel_history) : "")
                                            : "one shadow ray per pixel")
                               : "visibility off: the kept sample shaded with V = 1, no shadow rays");
        // By the setting, not plan.resamplePixels: a dark frame lists the pass it skips.
        if (particles && r.pixel_shading == PixelShading::interpolate)
            step(Pass::shadeParticlePixels, dark ? noLight : "interpolate: bilinear over the pixel's particle's texels' Lr (biased)");
        else if (particles)
            step(Pass::resampleParticlePixels,
                 dark ? noLight : "resample: the particle's bilinear texels' samples at the pixel's point, its own shadow ray (unbiased)");
        step(Pass::upsampleLighting,
             plan.upsample ? fmt::format("lighting at scale {}", s.restir.resolution_scale) : "full-resolution lighting");
    } else if (estimatorInfo(est).passes == LightingPasses::particleSplit) {
        const ParticleSplitSettings& ps = s.particle_split;
        step(Pass::gatherParticleTexels,
             dark ? noLight
                  : fmt::format("the visible particles in Morton order, {0}x{0} texels each{1}", ps.texels,
                                ps.texel_point == TexelPoint::centre ? ""
                                : fmt::format(", at points of their squares drawn each frame ({})", enumName(ps.texel_point))));
        step(Pass::findNearLights,
             dark ? noLight : fmt::format("each visible particle's {} nearest lights on the light tree (no rays)", ps.near));
        step(Pass::shadeSplitTexels,
             dark ? noLight
                  : fmt::format("per texel: the near lights summed and {} far rays, each {} from the light tree, {}{}", ps.far,
                                ps.candidates > 1 ? fmt::format("kept by RIS among {} draws", ps.candidates) : std::string("one draw"),
                                plan.shadowRays ? "a shadow ray each" : "visibility off (V = 1)",
                                ps.history <= 0.0 ? std::string()
                                : fmt::format("{}{}{}{}{}",
                                              ps.history_of == HistoryOf::far
                                                  ? fmt::format(", the far mean averaged with last frame's (h = {}), the near sum this frame's", ps.history)
                                                  : fmt::format(", Lr averaged with last frame's (h = {})", ps.history),
                                              ps.history_start == HistoryStart::mean ? ", a running mean over a texel's first frames" : "",
                                              ps.far_new > ps.far ? fmt::format(", {} far rays for a texel without history (a second launch over those texels)", ps.far_new) : "",
                                              ps.far_prior > 0 ? fmt::format(", a texel without history started from its near lights' far means (worth {} far rays)", ps.far_prior) : "",
                                              ps.far_share > 0 ? fmt::format(", every texel's far mean shown blended with its near lights' (worth {} far rays)", ps.far_share) : "")));
        step(Pass::shadeParticlePixels, dark ? noLight : "interpolate: bilinear over the pixel's particle's texels' Lr (biased)");
    } else if (estimatorInfo(est).passes == LightingPasses::voxelCache) {
        const VoxelSettings& v = s.voxel;
        step(Pass::updateVoxelCache,
             dark ? noLight
                  : fmt::format("{} cells along the longest side, those the particles reach: {} lights from {} each, {}, averaged "
                                "over up to {:g} frames", v.cells, v.rays, enumName(s.render.source),
                                plan.shadowRays ? "one shadow ray each" : "visibility off (V = 1)", v.history));
        step(Pass::shadeVoxelPixels,
             dark ? noLight : fmt::format("trilinear over the 8 cells around the pixel's point, its own light taken out, basis {}",
                                          enumName(v.basis)));
    } else {
        work("shadow rays", plan.shadowRays,
             plan.shadowRays ? "V by occlusion queries" : (dark ? noLight : "visibility off: no shadow rays"));
    }
    const bool reservoirs = plan.lighting && estimatorInfo(est).resampling;
    work("reservoirs", reservoirs,
         reservoirs ? fmt::format("{} B each", restir ? ReservoirCodec(s.restir).bytes() : 16)
                    : fmt::format("estimator {}: no reservoirs", enumName(est)));
    work("counters", plan.counting,
         plan.counting ? "counting variants of every pass" : "counters off: no counting code in the loops");
    step(Pass::composeImage, "Le + Lr");
    step(Pass::writeOutputs, "EXR, PNG previews, stats (by the command)");
}

}  // namespace

bool staticParticles(const ParticleSettings& p) {
    if (!p.file.empty()) return p.file.find("{frame}") == std::string::npos;
    return p.gm == 0.0 || p.time_step == 0.0;
}

bool emissive(const Particles& particles) {
    double total = 0.0;
    for (const Vec3& I : particles.emission) total += luminance(I);
    return total > 0.0;
}

bool needsPreviousBvh(const Settings& s) {
    return estimatorInfo(s.render.estimator).restirPasses() && s.restir.temporal &&
           s.restir.bias_correction == BiasCorrection::basic && s.restir.basic_visibility &&
           (s.restir.visibility_reuse || s.restir.candidate_visibility) &&
           (s.geometry.build == BuildPolicy::rebuild || s.geometry.build == BuildPolicy::fast_trace);
}

FramePlan planFrame(const Settings& settings, const FrameFacts& facts) {
    FramePlan plan;
    planRun(settings, plan);
    planPasses(settings, facts, plan);
    describe(settings, facts, plan);
    return plan;
}

bool FramePlan::runs(Pass pass) const {
    switch (pass) {
    case Pass::loadParticles: return loadParticles;
    case Pass::buildLightSampler: return sampler != LightSamplerKind::none;
    case Pass::chooseNearLights: return chooseNearLights;
    case Pass::buildClusters: return buildClusters;
    case Pass::traceGBuffer: return true;
    case Pass::estimateLighting: return lighting;
    case Pass::presampleLightTiles: return presampleTiles;
    case Pass::presampleRegirGrid: return presampleRegir;
    case Pass::generateCandidates: return restir;
    case Pass::temporalResampling: return temporal;
    case Pass::spatialResampling: return spatialIterations > 0 && !particleTexels;
    case Pass::resampleWorldNeighbours: return spatialIterations > 0 && particleTexels;
    case Pass::gatherParticleTexels: return particleTexels || particleSplit;
    case Pass::traceShadowRays: return traceShadowRays;
    case Pass::shadeParticlePixels: return (particleTexels && !resamplePixels) || particleSplit;
    case Pass::resampleParticlePixels: return resamplePixels;
    case Pass::updateVoxelCache: return voxelCache;
    case Pass::shadeVoxelPixels: return voxelCache;
    case Pass::findNearLights: return particleSplit;
    case Pass::shadeSplitTexels: return particleSplit;
    case Pass::upsampleLighting: return upsample;
    case Pass::composeImage: return true;
    case Pass::writeOutputs: return true;
    }
    return false;
}

std::vector<Pass> FramePlan::passes() const {
    std::vector<Pass> out;
    for (const PlannedStep& s : steps)
        if (s.pass && runs(*s.pass) && *s.pass != Pass::writeOutputs) out.push_back(*s.pass);
    return out;
}

const PlannedStep* FramePlan::find(Pass pass) const {
    for (const PlannedStep& s : steps)
        if (s.pass == pass) return &s;
    return nullptr;
}

std::string formatPlan(const FramePlan& plan) {
    std::string out;
    for (const PlannedStep& s : plan.steps) {
        const bool nested = s.pass && isNested(*s.pass);
        out += fmt::format("  {}{:<{}} {:<8} {}\n", nested ? "  " : "", s.name(), nested ? 22 : 24,
                           plan.runs(s) ? "runs" : "skipped", s.why);
    }
    return out;
}

}  // namespace accretion
