#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "accretion/geometry/embree_device.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/gpu/gpu_report.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/render/restir.h"
#include "accretion/particles/particle_source.h"
#include "accretion/geometry/camera.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/render/estimators.h"
#include "accretion/render/gbuffer.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/pixel_window.h"
#include "accretion/render/particle_split.h"
#include "accretion/render/voxel_cache.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Every per-pixel output of one frame (the EXR layers), each of the pixels
/// of `window` row by row (window.index(x, y)).
struct FrameImage {
    std::uint32_t width = 0, height = 0;  ///< the image's
    PixelWindow window;               ///< the pixels rendered (render.crop; the whole image by default)
    CameraPose camera;                ///< the frame's camera in world space (its jitter included)
    std::vector<Vec3> L;              ///< pixel value: Le + Lr, or the background
    std::vector<Vec3> Le;             ///< self-emission s_e I_j
    LightingImage lighting;           ///< Lr, its standard error, spp
    std::vector<float> depth;         ///< camera-space z, +inf on a miss
    std::vector<Vec3> normal;         ///< shading normal
    std::vector<std::uint32_t> particle; ///< hit particle id, kNoParticle on a miss
    ReservoirImage reservoirs;        ///< restir only: the final reservoirs
    FrameCounters counters;           ///< gpu.counters: every pass's thread records
    std::vector<Heatmap> heatmaps;    ///< gpu.counters: per-pixel counter AOVs (gpu.*)
};

/// Counts and times of one frame, for stats.json.
struct FrameStats {
    std::uint32_t frame = 0;
    Vec3 origin{0.0f};                ///< world position of the frame coordinates' origin (the camera)
    std::size_t particles = 0;
    BvhStats bvh;
    std::uint64_t primaryRays = 0;
    LightingCounters lighting;
    std::size_t lightTreeNodes = 0;   ///< tree: nodes of the light tree
    NearLightChoice nearLights;       ///< split with render.near_lights = 0: the pilot's choice of k
    std::size_t reservoirBytes = 0;   ///< restir: bytes per stored reservoir
    double meanSpp = 0.0;             ///< light samples per hit pixel, mean (adaptive sampling varies it)
    double maxSpp = 0.0;              ///< and maximum
    std::size_t hitPixels = 0;
    PassRejections nonFinite;         ///< NaN/Inf rejected per pass (estimateLighting or the restir passes, composeImage)
    PassReuse reuse;                  ///< restir: reuse offers by outcome, per pass
    PassTimer timer;                  ///< wall time per pass name
    double seconds = 0.0;             ///< whole frame
};

/// Checkpointing and sharding of the lighting pass of an accumulating
/// estimator (exact, uniform, power, tree, ris).
struct LightingSession {
    Shard shard;                          ///< this process's part of the chunks
    const Accumulation* resume = nullptr; ///< continue from these sums (a checkpoint of this frame)
    ChunkHook afterChunk;                 ///< after each chunk: may checkpoint, may throw Interrupted
    Accumulation* result = nullptr;       ///< receives the frame's sums (a shard's output)
};

struct RenderOptions {
    bool quiet = false;  ///< no progress on stderr
    bool rebuildStatic = false;  ///< benchmarks: rebuild a static scene every frame (to time the skip)
};

/// Renders frames of a scene: each frame executes its FramePlan
/// (loadParticles, buildClusters, buildLightSampler, traceGBuffer,
/// estimateLighting or the restir passes, composeImage) and decides nothing
/// else. Keeps the Embree device and BVH across frames (refit needs them).
///
/// Lanes: several settings of one scene that differ only in render.seed,
/// render.crop and restir.crop_margin (the seeds and crops of an
/// experiment). Each frame's particles, BVH and light sampler are built once;
/// each lane traces and lights its own view of them, restir with its own
/// history, and gets the image a renderer of its settings alone would give.
class FrameRenderer {
public:
    FrameRenderer(const Settings& settings, ParticleSource source, RenderOptions options = {});
    /// Throws std::invalid_argument where the lanes differ in anything but
    /// their seed and crop, or count GPU work (gpu.counters: one BVH's counts).
    FrameRenderer(std::vector<Settings> lanes, ParticleSource source, RenderOptions options = {});
    ~FrameRenderer();

    /// Render one frame of the one lane; the passes' times go to stats.timer.
    /// With a trace (render --pixel), the lighting of pixel trace->px is recorded in it.
    FrameImage render(std::uint32_t frame, FrameStats& stats, const LightingSession* session = nullptr,
                      PixelTrace* trace = nullptr);

    /// Render one frame of every lane: the geometry's passes (loadParticles,
    /// buildClusters, buildLightSampler) timed in `shared`, each lane's own in
    /// laneStats[k] (resized to the lanes).
    std::vector<FrameImage> renderLanes(std::uint32_t frame, FrameStats& shared, std::vector<FrameStats>& laneStats);

    std::size_t lanes() const { return lanes_.size(); }
    const Settings& settings() const { return lanes_[0].settings; }
    /// The BVH of the last frame rendered.
    const ParticleBvh& bvh() const { return *bvh_; }
    /// The plan of the last frame rendered (before the first: of the first
    /// frame, as far as the settings tell); the first lane's.
    const FramePlan& plan() const { return lanes_[0].plan; }

private:
    /// One view of the frame: its settings, this frame's plan, its restir history.
    struct Lane {
        Settings settings;
        FramePlan plan;
        std::unique_ptr<Restir> restir;
        std::unique_ptr<VoxelCache> voxel;  ///< voxel_cache: the world's cells, kept from frame to frame
        std::unique_ptr<ParticleSplit> split;  ///< particle_split: last frame's texels, by particle id
    };
    /// What every lane of a frame shares: the camera, the particles and the light sampler.
    struct FrameGeometry;

    /// The frame's camera and origin, loadParticles and buildClusters as the
    /// plan says, and buildLightSampler; plans each lane's frame (the plan
    /// needs to know whether the particles emit).
    void prepareFrame(std::uint32_t frame, FrameGeometry& g, FrameStats& stats);
    /// traceGBuffer, lighting and composeImage of one lane's view.
    FrameImage renderLane(Lane& lane, std::uint32_t frame, const FrameGeometry& g, FrameStats& stats,
                          const LightingSession* session, PixelTrace* trace);
    /// chooseNearLights: split's k for this frame (render.near_lights = 0),
    /// from a pilot on the frame's view at 64 pixels across.
    std::uint32_t chooseFrameNearLights(const Lane& lane, std::uint32_t frame, const FrameGeometry& g, FrameStats& stats);
    /// estimateLighting (the restir passes for restir) into img.lighting, or Lr = 0 unlit.
    void lightFrame(Lane& lane, std::uint32_t frame, const Camera& camera, const FrameGeometry& g, const GBuffer& gbuffer,
                    const LightingSession* session, PixelTrace* trace, FrameImage& img, FrameStats& stats);

    std::vector<Lane> lanes_;
    CameraTrack cameras_;  ///< every frame's camera: the path, or the engine's file
    ParticleSource source_;
    Particles staticParticles_;  ///< static scenes: loaded once
    bool built_ = false;         ///< the BVH has been built once
    Vec3 origin_{0.0f};          ///< world position of the frame coordinates' origin
    RenderOptions options_;
    std::unique_ptr<EmbreeDevice> device_;
    std::unique_ptr<ParticleBvh> bvh_;
    std::unique_ptr<ParticleBvh> previousBvh_;  ///< last frame's, when needsPreviousBvh()
};

}  // namespace accretion
