#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/reservoir_codec.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/estimators.h"
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
    std::uint32_t frame = 0;
    const AliasTable* powerTable = nullptr;  ///< render.source = power
    const ParticleBvh* previousBvh = nullptr; ///< last frame's BVH (see needsPreviousBvh), else the current one is used
    FrameCounters* counters = nullptr;        ///< counting mode: each pass adds its thread records (the BVH must count)
};

/// basic_visibility tests the previous frame's samples against the previous
/// frame's geometry: the frame renderer keeps that BVH (for rebuild and
/// fast_trace policies; refit and partial update one BVH in place).
bool needsPreviousBvh(const Settings& settings);

/// ReSTIR DI (MODEL.md section 4; Bitterli et al. 2020): generateCandidates
/// (RIS, M candidates, target p_hat without visibility), temporalResampling
/// (reprojection through particle motion and the previous camera, rejection
/// on particle / normal / depth, history M capped at C x M), k-neighbour
/// spatialResampling (1 or more passes), traceShadowRays (one shadow ray
/// for the kept sample, optionally zeroing an occluded sample before it is
/// stored), and upsampleLighting when lighting runs at reduced resolution.
/// Reusing a sample y of reservoir i at pixel q weighs it by
/// p_hat_q(y) W_i M_i (bias correction none / basic) or by the pairwise MIS
/// weight. Keeps the previous frame's G-buffer, particles, camera and
/// reservoirs: the history starts with the first frame rendered.
class Restir {
public:
    /// keepHistory: keep this frame for the next one's temporal reuse
    /// (false for one frame or temporal off: no history buffers or motion).
    Restir(const Settings& settings, bool keepHistory);

    /// Render Lr of one frame (spp = 1, no per-pixel standard error). Values
    /// that overflow or go NaN are rejected under render.nonfinite, counted
    /// per pixel (out.rejected) and per pass (`rejected`).
    LightingCounters render(const RestirInputs& in, LightingImage& out, ReservoirImage& aov, PassTimer& timer,
                            PassRejections& rejected);

    /// Bytes of the stored reservoirs per lighting pixel, and of the history.
    std::size_t reservoirBytes() const { return codec_.bytes(); }
    const ReservoirCodec& codec() const { return codec_; }

    struct History;  ///< previous frame (defined in restir.cpp)

private:
    RestirSettings rs_;
    bool keepHistory_;
    ReservoirCodec codec_;
    std::shared_ptr<History> history_;
};

}  // namespace accretion
