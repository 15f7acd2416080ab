#include "accretion/render/pass_plan.h"

#include <fmt/format.h>

#include "accretion/core/pass_timer.h"
#include "accretion/lighting/restir.h"

namespace accretion {

bool staticParticles(const ParticleSettings& p) {
    if (!p.file.empty()) return p.file.find("{frame}") == std::string::npos;
    return p.gm == 0.0 || p.time_step == 0.0;
}

PassPlan planPasses(const Settings& s) {
    PassPlan plan;
    const EstimatorKind est = s.render.estimator;
    const bool restir = est == EstimatorKind::restir;
    const bool staticCamera = s.camera.path == CameraPath::static_pose ||
                              (s.camera.path == CameraPath::orbit && s.camera.orbit_speed == 0.0);
    const bool manyFrames = s.render.frames > 1;
    plan.staticGeometry = staticParticles(s.particles) && staticCamera;
    plan.alphaFilter = s.geometry.primitive == Primitive::billboard && s.geometry.alpha == AlphaMode::disc;
    const bool dark = glm::length(s.shading.albedo) == 0.0f || (s.particles.file.empty() && s.particles.luminosity == 0.0);
    plan.lighting = !dark;
    plan.shadowRays = plan.lighting && s.shading.visibility;
    const bool powerSource = (est == EstimatorKind::ris || restir) && s.render.source == LightSource::power;
    plan.lightSampler = plan.lighting && (est == EstimatorKind::power || est == EstimatorKind::tree || powerSource);
    plan.reservoirs = plan.lighting && (est == EstimatorKind::ris || restir);
    plan.history = plan.lighting && restir && s.restir.temporal && manyFrames;
    plan.spatial = plan.lighting && restir && s.restir.spatial_neighbours > 0 && s.restir.spatial_iterations > 0;
    plan.upsample = plan.lighting && restir && s.restir.resolution_scale < 1.0;
    // A static scene's one BVH is also last frame's.
    plan.previousBvh = plan.history && plan.shadowRays && !plan.staticGeometry && needsPreviousBvh(s);
    plan.counting = s.gpu.counters;

    auto step = [&](std::string_view name, bool runs, std::string why) {
        plan.steps.push_back({std::string(name), runs, std::move(why)});
    };
    step(pass::loadParticles, true,
         plan.staticGeometry && manyFrames ? "once: the particles do not move" : "every frame");
    step(pass::buildClusters, true,
         plan.staticGeometry ? (manyFrames ? "once for all frames: static particles and camera" : "one frame")
                             : fmt::format("every frame ({})", enumName(s.geometry.build)));
    step("alpha filter callbacks", plan.alphaFilter,
         plan.alphaFilter ? (s.gpu.omm == OmmMode::off ? "disc alpha: any-hit on every candidate"
                                                       : fmt::format("disc alpha with {} OMM level {}", enumName(s.gpu.omm), s.gpu.omm_level))
                          : "no alpha test (opaque quads or spheres)");
    step("previous-frame BVH", plan.previousBvh,
         plan.previousBvh ? "basic_visibility tests history samples against last frame's geometry"
                          : "not needed (no basic_visibility with history and visibility reuse)");
    step(pass::buildLightSampler, plan.lightSampler,
         plan.lightSampler ? (est == EstimatorKind::tree ? "light tree" : "alias table over light power")
                           : (plan.lighting ? fmt::format("{} samples lights uniformly", enumName(est)) : "no lighting"));
    step(pass::traceGBuffer, true, "one primary ray per pixel");
    const std::string noLight = dark ? "no lighting passes: albedo 0 or no emission" : "";
    if (restir) {
        step(pass::generateCandidates, plan.lighting, plan.lighting ? fmt::format("{} candidates", s.render.candidates) : noLight);
        step(pass::temporalResampling, plan.history,
             plan.history ? "reprojection through particle motion"
                          : (!plan.lighting ? noLight : !s.restir.temporal ? "temporal off: no history buffers or motion"
                                                                             : "one frame: no history buffers or motion"));
        step(pass::spatialResampling, plan.spatial,
             plan.spatial ? fmt::format("{} neighbours x {}", s.restir.spatial_neighbours, s.restir.spatial_iterations)
                          : (plan.lighting ? "no neighbours" : noLight));
        step(pass::traceShadowRays, plan.shadowRays,
             plan.shadowRays ? "one shadow ray per pixel" : (plan.lighting ? "visibility off: no shadow rays" : noLight));
        step(pass::upsampleLighting, plan.upsample,
             plan.upsample ? fmt::format("lighting at scale {}", s.restir.resolution_scale) : "full-resolution lighting");
    } else {
        step(pass::estimateLighting, plan.lighting, plan.lighting ? std::string(enumName(est)) : noLight);
        step("shadow rays", plan.shadowRays,
             plan.shadowRays ? "V by occlusion queries" : (plan.lighting ? "visibility off: no shadow rays" : noLight));
    }
    step("reservoirs", plan.reservoirs,
         plan.reservoirs ? fmt::format("{} B each", restir ? ReservoirCodec(s.restir).bytes() : 16)
                         : fmt::format("estimator {}: no reservoirs", enumName(est)));
    step("counters", plan.counting,
         plan.counting ? "counting variants of every pass" : "counters off: no counting code in the loops");
    step(pass::composeImage, true, "Le + Lr");
    step(pass::writeOutputs, true, "EXR, PNG previews, stats");
    return plan;
}

std::string formatPlan(const PassPlan& plan) {
    std::string out;
    for (const PlannedStep& s : plan.steps)
        out += fmt::format("  {:<24} {:<8} {}\n", s.name, s.runs ? "runs" : "skipped", s.why);
    return out;
}

}  // namespace accretion
