#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/geometry/camera.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/render/estimators.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/gbuffer.h"
#include "accretion/render/voxel_grid.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// What one voxel_cache frame reads.
struct VoxelInputs {
    const ParticleBvh& bvh;
    const Particles& particles;
    const GBuffer& gbuffer;     ///< the whole frame (or its window)
    const Camera& camera;
    const Settings& settings;
    const FramePlan& plan;
    std::uint32_t frame = 0;
    const AliasTable* powerTable = nullptr;  ///< render.source power (the plan built it)
    const LightTree* lightTree = nullptr;    ///< render.source tree (the plan built it); neither: uniform
    Vec3 origin{0.0f};                       ///< the frame's origin in the world (FrameRenderer's)
    FrameCounters* counters = nullptr;       ///< counting mode: each pass adds its thread records
};

/// seed 004's voxel radiance cache (voxel_cache_passes.h): a world-space
/// grid kept from frame to frame. updateVoxelCache marks the cells the
/// particles reach and updates each with voxel.rays lights from render.source, one
/// shadow ray each, averaged over up to voxel.history frames;
/// shadeVoxelPixels reads them at each hit pixel. The grid is placed once
/// and again (its history dropped) only when a particle leaves it.
class VoxelCache {
public:
    explicit VoxelCache(const Settings& settings) : vs_(settings.voxel) {}

    /// Render Lr of one frame (spp = 1, no per-pixel standard error).
    LightingCounters render(const VoxelInputs& in, LightingImage& out, PassTimer& timer);


private:
    VoxelSettings vs_;
    VoxelPlacement placement_;
    std::vector<voxel::VoxelCell> cells_;
};

}  // namespace accretion
