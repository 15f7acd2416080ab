#pragma once
// The per-pixel steps of the twin's restir passes (restir_kernels.cu and the
// shading raygens of programs.cu): the CPU passes of src/render/restir/ written
// again for one GPU thread, on the functions both share (evalLight, Reservoir,
// the resampling weights, PortableRng), so that a GPU frame draws the CPU
// frame's candidates and keeps its samples.
#include <cmath>

#include "accretion/core/rng.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/resampling.h"
#include "accretion/lighting/shading.h"
#include "launch_params.h"

namespace accretion::twin {

/// Offers of one resampling step: the canonical reservoir and up to 64 neighbours.
inline constexpr std::uint32_t kMaxOffers = 65;

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

__device__ inline bool finiteF(float v) { return isfinite(v); }

/// FrameContext::reject: count a non-finite value at px; true if the policy discards.
__device__ inline bool rejectAt(const RestirParams& p, std::size_t px) {
    ++p.rejected[px];
    return p.discardNonFinite;
}

/// FrameContext::sanitize.
__device__ inline StoredReservoir sanitize(const RestirParams& p, StoredReservoir r, std::size_t px) {
    if (finiteF(r.W) && finiteF(r.p_hat)) return r;
    if (rejectAt(p, px)) return StoredReservoir{};
    return StoredReservoir{kNoLight, 0.0f, r.M, 0.0f};
}

struct Offer {
    StoredReservoir r;
    ShadingPoint sp;
    const LightView* lights;
};

/// combineReservoirs (src/render/restir/combine_reservoirs.h) without
/// basic_visibility: the same weights, in the same order, from the same stream.
template <ShadingModel SM>
__device__ StoredReservoir combineReservoirs(const Offer* offers, std::uint32_t n, const LightView& L, BiasCorrection bias,
                                             PortableRng& rng) {
    const Offer& can = offers[0];
    const ShadingPoint& sp = can.sp;
    if (n == 1) return can.r;
    double Mtotal = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) Mtotal += offers[i].r.M;
    float pc[kMaxOffers];
    pc[0] = can.r.W > 0.0f ? can.r.p_hat : 0.0f;
    for (std::uint32_t i = 1; i < n; ++i) pc[i] = offers[i].r.W > 0.0f ? targetPdf<SM>(L, sp, offers[i].r.y) : 0.0f;

    Reservoir out;
    StoredReservoir res;
    res.M = static_cast<std::uint32_t>(Mtotal < 4294967295.0 ? Mtotal : 4294967295.0);
    if (bias == BiasCorrection::pairwise) {
        const double k = n - 1;
        const double Mc = can.r.M;
        for (std::uint32_t i = 0; i < n; ++i) {
            const StoredReservoir& r = offers[i].r;
            double m = 0.0;
            if (r.W > 0.0f && pc[i] > 0.0f) {
                if (i == 0) {
                    for (std::uint32_t j = 1; j < n; ++j) {
                        const double pj = targetPdf<SM>(*offers[j].lights, offers[j].sp, r.y);
                        m += resampling::pairwiseCanonicalTerm(offers[j].r.M, pj, Mc, k, pc[0], Mtotal);
                    }
                } else {
                    m = resampling::pairwiseNeighbourWeight(r.M, r.p_hat, Mc, k, pc[i], Mtotal);
                }
            }
            const float w = static_cast<float>(m * double(pc[i]) * double(r.W));
            out.merge(r.y, w, pc[i], r.M, rng.uniform());
        }
        if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
        res.y = out.y;
        res.p_hat = out.p_hat;
        res.W = out.w_sum / out.p_hat;
        return res;
    }
    std::uint32_t chosen = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        const StoredReservoir& r = offers[i].r;
        const float w = pc[i] * r.W * float(r.M);
        if (out.merge(r.y, w, pc[i], r.M, rng.uniform())) chosen = i;
    }
    if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
    double Z = Mtotal;
    if (bias == BiasCorrection::basic) {  // resampling::basicNormalization, in domain order
        Z = offers[chosen].r.M;
        for (std::uint32_t i = 0; i < n; ++i) {
            if (i == chosen) continue;
            LightTerm t;
            if (lightTerm<SM>(*offers[i].lights, offers[i].sp, out.y, t) && luminance(t.value) > 0.0f) Z += offers[i].r.M;
        }
    }
    res.y = out.y;
    res.p_hat = out.p_hat;
    res.W = static_cast<float>(double(out.w_sum) / (Z * double(out.p_hat)));
    return res;
}

}  // namespace accretion::twin
