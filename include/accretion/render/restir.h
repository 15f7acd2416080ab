#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "accretion/geometry/camera.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/lighting/reservoir_codec.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/estimators.h"
#include "accretion/render/frame_plan.h"
#include "accretion/render/gbuffer.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Per-pixel reservoir AOVs of a restir frame (restir.W, .M, .light, .p_hat).
struct ReservoirImage {
    std::vector<float> W;
    std::vector<float> M;
    std::vector<std::uint32_t> light;  ///< kNoLight when empty
    std::vector<float> p_hat;
    bool empty() const { return W.empty(); }
};

/// What one restir frame reads.
struct RestirInputs {
    const ParticleBvh& bvh;
    const Particles& particles;
    const GBuffer& gbuffer;      ///< full resolution
    const Camera& camera;
    const Settings& settings;
    const FramePlan& plan;       ///< the passes to run (temporal, spatial iterations, upsample)
    std::uint32_t frame = 0;
    const AliasTable* powerTable = nullptr;  ///< candidates in proportion to power (the plan built it)
    const LightTree* lightTree = nullptr;    ///< candidates from the light tree (the plan built it); neither: uniform
    const ParticleBvh* previousBvh = nullptr; ///< last frame's BVH (see needsPreviousBvh), else the current one is used
    FrameCounters* counters = nullptr;        ///< counting mode: each pass adds its thread records (the BVH must count)
    PixelTrace* trace = nullptr;              ///< render --pixel: the reservoir of trace->px after each pass
};

/// ReSTIR DI (docs/MODEL.md section 4; Bitterli et al. 2020): generateCandidates
/// (RIS, M candidates, target p_hat without visibility), temporalResampling
/// (reprojection through particle motion and the previous camera, rejection
/// on particle / normal / depth, history M capped at C x M), k-neighbour
/// spatialResampling (1 or more passes), traceShadowRays (one shadow ray
/// for the kept sample, optionally zeroing an occluded sample before it is
/// stored), and upsampleLighting when lighting runs at reduced resolution.
/// Reusing a sample y of reservoir i at pixel q weighs it by
/// p_hat_q(y) W_i M_i (bias correction none / basic) or by the pairwise MIS
/// weight (lighting/resampling.h). Keeps the previous frame's G-buffer,
/// particles, camera and reservoirs: the history starts with the first
/// frame rendered. One file per pass in src/render/restir/, named like it.
class Restir {
public:
    /// keepHistory: keep this frame for the next one's temporal reuse
    /// (false for one frame or temporal off: no history buffers or motion).
    Restir(const Settings& settings, bool keepHistory);

    /// Render Lr of one frame (spp = 1, no per-pixel standard error). Values
    /// that overflow or go NaN are rejected under render.nonfinite, counted
    /// per pixel (out.rejected) and per pass (`rejected`); the reuse
    /// offers of each pass by outcome are added to `reuse`.
    LightingCounters render(const RestirInputs& in, LightingImage& out, ReservoirImage& aov, PassTimer& timer,
                            PassRejections& rejected, PassReuse& reuse);

    /// A previous frame is kept for temporal reuse (FrameFacts::historyAvailable).
    bool hasHistory() const { return history_ != nullptr; }

    /// Bytes of the stored reservoirs per lighting pixel, and of the history.
    std::size_t reservoirBytes() const { return codec_.bytes(); }
    const ReservoirCodec& codec() const { return codec_; }

    struct History;  ///< previous frame (src/render/restir/restir_pass.h)

private:
    RestirSettings rs_;
    bool keepHistory_;
    ReservoirCodec codec_;
    std::shared_ptr<History> history_;
};

}  // namespace accretion
