#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "accretion/core/pass.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/render/pixel_window.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// One line of a frame's plan, as `accretion plan` prints it: a pass (whether
/// it runs is FramePlan::runs, decided once) or the work inside one, with
/// what it does or why it is skipped.
struct PlannedStep {
    std::optional<Pass> pass;  ///< a timed pass (stats' "passes"), else work inside one, named by `work`
    std::string work;
    bool workRuns = true;      ///< the work's (a pass's is the plan's)
    std::string why;
    std::string_view name() const { return pass ? passName(*pass) : std::string_view(work); }
};

/// What the frame renderer knows of a frame before it plans it.
struct FrameFacts {
    bool geometryBuilt = false;     ///< a static scene's particles and BVH are already built
    bool historyAvailable = false;  ///< restir: a previous frame's reservoirs are kept
    bool emissive = true;           ///< some particle emits (luminance > 0)
    bool lightingSkipped = false;   ///< the command times the geometry alone (accretion-optix --skip-lighting)
};

/// Everything a frame runs, decided once from the settings and the facts;
/// FrameRenderer and Restir execute it and decide nothing themselves.
/// `accretion plan` prints it, and stats.json's "passes" of a frame are
/// exactly passes() (plus writeOutputs, which the command runs).
struct FramePlan {
    // Run-wide decisions (the same every frame).
    bool staticGeometry = false;  ///< static particles and camera: one BVH build for all frames
    /// geometry.build refit or partial: one BVH updated in place from frame
    /// to frame, in the coordinates of its first build (its origin kept).
    bool updateInPlace = false;
    bool alphaFilter = false;     ///< disc alpha: filter (any-hit) callbacks attached
    bool keepHistory = false;     ///< restir temporal reuse over several frames: history buffers and motion kept
    bool previousBvh = false;     ///< a second BVH kept for basic_visibility
    bool counting = false;        ///< counter code compiled into the loops
    /// The pixels traced and lit, and the size of every per-pixel buffer:
    /// render.crop's window where cropRendersAlone (settings.h), else the
    /// whole image, whose layers are cut to the crop after the frame.
    PixelWindow traced;
    /// The part of the image the frame renders as an image of its own: the
    /// whole image, or for restir with restir.crop_margin render.crop and
    /// that margin around it (aligned to 8 pixels, within the image), seen
    /// through Camera::window. `traced` is then that window, whole.
    PixelWindow frameWindow;
    // This frame.
    bool loadParticles = true;    ///< load (or generate) the particles
    bool buildClusters = true;    ///< build (or refit) the BVH
    bool lighting = true;         ///< any lighting pass at all
    LightSamplerKind sampler = LightSamplerKind::none;  ///< buildLightSampler
    bool chooseNearLights = false;  ///< split's pilot picks render.near_lights (set to 0) for the frame
    bool shadowRays = true;       ///< visibility by shadow rays (off: V = 1)
    bool restir = false;          ///< the restir passes instead of estimateLighting's accumulation
    bool presampleTiles = false;  ///< presampleLightTiles (render.source tiles or regir)
    bool presampleRegir = false;  ///< presampleRegirGrid (render.source regir)
    bool temporal = false;        ///< temporalResampling
    std::uint32_t spatialIterations = 0;  ///< spatialResampling runs
    bool upsample = false;        ///< upsampleLighting (restir at reduced resolution)
    /// particle_restir: gatherParticleTexels and shadeParticlePixels (or
    /// resampleParticlePixels) around the reservoir passes, which run on the texels.
    bool particleTexels = false;
    /// particle_restir with restir.pixel_shading resample: resampleParticlePixels
    /// (the pixel resamples its particle's texels' samples and traces its own
    /// shadow ray) instead of shadeParticlePixels' interpolation.
    bool resamplePixels = false;
    /// traceShadowRays runs: restir's pixels, particle_restir's texels when
    /// the pixels interpolate their Lr (or visibility reuse needs their V).
    bool traceShadowRays = false;
    /// particle_restir with restir.texel_history: the texels' Lr averaged
    /// with last frame's (in traceShadowRays, whose kernel it ends).
    bool texelHistory = false;
    /// voxel_cache: updateVoxelCache and shadeVoxelPixels instead of restir's passes.
    bool voxelCache = false;
    /// particle_split: gatherParticleTexels, findNearLights, shadeSplitTexels
    /// and shadeParticlePixels instead of restir's passes.
    bool particleSplit = false;
    std::vector<PlannedStep> steps;

    /// Whether a frame with these facts loads (and builds) its particles: the
    /// run-wide half of the decision, which the frame renderer needs before
    /// the particles it plans with are loaded.
    bool loadsParticles(const FrameFacts& facts) const { return !(staticGeometry && facts.geometryBuilt); }
    /// Whether a pass runs this frame: the one mapping of the decisions above to passes.
    bool runs(Pass pass) const;
    /// Whether a line of steps runs.
    bool runs(const PlannedStep& step) const { return step.pass ? runs(*step.pass) : step.workRuns; }
    /// The passes that run, in order (restir's inside estimateLighting), writeOutputs aside.
    std::vector<Pass> passes() const;
    const PlannedStep* find(Pass pass) const;
};

/// The plan of one frame.
FramePlan planFrame(const Settings& settings, const FrameFacts& facts);

/// Some particle emits.
bool emissive(const Particles& particles);

/// basic_visibility tests the previous frame's samples against the previous
/// frame's geometry: the frame renderer keeps that BVH (for rebuild and
/// fast_trace policies; refit and partial update one BVH in place).
bool needsPreviousBvh(const Settings& settings);

/// Particles identical in every frame (generator without motion, or one file without {frame}).
bool staticParticles(const ParticleSettings& particles);

/// "name   runs/skipped  why" lines.
std::string formatPlan(const FramePlan& plan);

}  // namespace accretion
