#pragma once
// What the twin's restir kernels (restir_kernels.cu) and shading raygens
// (programs.cu) read of a frame: the adapters through which they run the
// per-pixel steps they share with the CPU (accretion/render/restir_steps.h),
// so that a GPU frame draws the CPU frame's candidates and keeps its samples.
#include <cmath>

#include "accretion/core/rng.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/resampling.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/restir_steps.h"
#include "launch_params.h"

namespace accretion::twin {

using restir::kMaxOffers;

__device__ inline ShadingPoint shadingPointOf(const GBufferTexel& g, const LightView& L) {
    const Vec3 centre = L.position[g.particle];
    return {centre + g.local, g.normal, g.geomNormal, L.albedo[g.particle], g.particle, centre, g.local};
}

/// LightArrays::term: light i's unshadowed term at sp (0 for its own particle).
template <ShadingModel SM>
__device__ inline bool lightTerm(const LightView& L, const ShadingPoint& sp, std::uint32_t i, LightTerm& t) {
    if (i == sp.self || i >= L.count) return false;
    return evalLight<SM>(sp, L.position[i], L.emission[i], L.dmin2[i], t);
}

/// LightArrays::targetPdf: p_hat = luminance(f I G), no visibility.
template <ShadingModel SM>
__device__ inline float targetPdf(const LightView& L, const ShadingPoint& sp, std::uint32_t i) {
    LightTerm t;
    return lightTerm<SM>(L, sp, i, t) ? luminance(t.value) : 0.0f;
}

/// FrameContext::reject: count a non-finite value at px; true if the policy discards.
__device__ inline bool rejectAt(const RestirParams& p, std::size_t px) {
    ++p.rejected[px];
    return p.discardNonFinite;
}


struct Offer {
    StoredReservoir r;
    ShadingPoint sp;
    const LightView* lights;
};

/// The offers of a kernel as restir_steps.h's Domains (combineReservoirs):
/// each domain's p_hat from its own lights; nothing counted; basic's support
/// is p_hat > 0 (the twin has no basic_visibility).
template <ShadingModel SM>
struct DeviceDomains {
    const Offer* offers;
    std::uint32_t n;

    __device__ std::uint32_t count() const { return n; }
    __device__ const StoredReservoir& reservoir(std::uint32_t i) const { return offers[i].r; }
    __device__ float targetPdf(std::uint32_t i, std::uint32_t y) const {
        return twin::targetPdf<SM>(*offers[i].lights, offers[i].sp, y);
    }
    __device__ void countTerm() const {}
    __device__ bool supports(std::uint32_t i, std::uint32_t y) const {
        LightTerm t;
        return lightTerm<SM>(*offers[i].lights, offers[i].sp, y, t) && luminance(t.value) > 0.0f;
    }
};

}  // namespace accretion::twin
