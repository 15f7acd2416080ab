#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/geometry/camera.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/render/estimators.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/gbuffer.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// What one particle_split frame reads.
struct ParticleSplitInputs {
    const ParticleBvh& bvh;
    const Particles& particles;
    const GBuffer& gbuffer;     ///< the whole frame
    const Camera& camera;
    const Settings& settings;
    const FramePlan& plan;
    std::uint32_t frame = 0;
    const LightTree& lightTree;          ///< the plan's buildLightSampler: the near search and the far draws
    FrameCounters* counters = nullptr;   ///< counting mode: each pass adds its thread records
};

/// seed 004's hybrid compute, per particle (particle_split_passes.h):
/// gatherParticleTexels, findNearLights, shadeSplitTexels and
/// shadeParticlePixels. Keeps last frame's texels' Lr by particle id for
/// particle_split.history.
class ParticleSplit {
public:
    explicit ParticleSplit(const Settings& settings) : ps_(settings.particle_split) {}

    /// Render Lr of one frame (spp 1 on hit pixels, no per-pixel standard
    /// error; `rejected` counts the non-finite far draws of the pixel's particle's texels).
    LightingCounters render(const ParticleSplitInputs& in, LightingImage& out, PassTimer& timer);

private:
    ParticleSplitSettings ps_;
    std::vector<std::uint32_t> prevSlotOf_;  ///< last frame's slot of each particle (kNoSlot: not seen)
    std::vector<Vec3> prevTexelLr_;          ///< last frame's texels' Lr
    std::vector<Vec3> prevTexelFar_;         ///< and their far means' average (history_of far)
    std::vector<std::uint32_t> prevTexelAge_;  ///< and the frames each has been seen (history_start mean)
    std::vector<std::uint32_t> prevNear_, prevNearFound_;  ///< far_handoff: last frame's near lights by its slots
    std::vector<Vec3> prevTexelNear_;                      ///< and its texels' near terms
};

}  // namespace accretion
