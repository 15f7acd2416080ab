#pragma once
// The per-pixel steps of ReSTIR DI (docs/MODEL.md section 4), one definition
// for both back ends: the CPU passes of src/render/restir/ and the GPU
// twin's kernels (src/twin/restir_kernels.cu) call these, so a change to
// the estimator reaches both or neither. Inputs are fixed-size; the frame is
// reached through small adapters (the Domains of combineReservoirs), which on
// the CPU also count what a GPU thread would do and on the GPU do nothing.
// tests/twin/shared_core_check.cu runs every step on the GPU and on the CPU
// on the same inputs: bit for bit, but for neighbourPoint's cos and sin.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/geometry/camera.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/reservoir_codec.h"
#include "accretion/lighting/resampling.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/settings.h"

namespace accretion::restir {

/// Offers of one resampling step: the canonical reservoir and up to 64
/// neighbours (restir.spatial_neighbours is at most 64).
inline constexpr std::uint32_t kMaxOffers = 65;

/// generateCandidates's RIS: `count` candidates, each drawn by draw(rng)
/// (a LightSample; pdf 0: no light, a zero candidate) and weighted p_hat /
/// pdf with p_hat = target(light). A non-finite weight makes a zero
/// candidate and calls reject(), as does a finite sum that overflowed;
/// reject() returns true when the policy (render.nonfinite) discards the
/// reservoir. Returns false when it is discarded.
template <class RngT, class Draw, class Target, class Reject>
ACC_HD bool resampleCandidates(std::uint32_t count, RngT& rng, Draw&& draw, Target&& target, Reject&& reject,
                               Reservoir& r) {
    bool discard = false;
    for (std::uint32_t m = 0; m < count; ++m) {
        const LightSample x = draw(rng);
        float p_hat = target(x.i);
        float w = x.pdf > 0.0f ? p_hat / x.pdf : 0.0f;
        if (!isFiniteNumber(w) || !isFiniteNumber(p_hat)) {
            discard = reject() || discard;
            w = p_hat = 0.0f;
        }
        r.update(x.i, w, p_hat, rng.uniform());
    }
    r.finalize();
    if (!isFiniteNumber(r.w_sum) || !isFiniteNumber(r.W)) {
        discard = reject() || discard;
        r.W = 0.0f;
    }
    return !discard;
}

/// A combined reservoir whose weights overflowed or went NaN: reject() counts
/// it and says whether render.nonfinite discards it (an empty reservoir);
/// zero_sample keeps its M with W = 0. A finite one is returned as it is.
template <class Reject>
ACC_HD StoredReservoir sanitizeReservoir(const StoredReservoir& r, Reject&& reject) {
    if (isFiniteNumber(r.W) && isFiniteNumber(r.p_hat)) return r;
    if (reject()) return StoredReservoir{};
    return StoredReservoir{kNoLight, 0.0f, r.M, 0.0f};
}

/// Spatial reuse's neighbour point of texel (x, y): uniform in the disc of
/// `radius` texels (polar, sqrt for area), in continuous texel coordinates.
/// Draws two numbers. cos and sin are the host's libm and the device's
/// cosf/sinf (2 ulp, CUDA's documented bound): the point may differ by a few
/// ulp between the hosts (tests/twin/shared_core_check.cu measures it).
template <class RngT>
ACC_HD void neighbourPoint(RngT& rng, float radius, std::uint32_t x, std::uint32_t y, float& fx, float& fy) {
    const float r = radius * std::sqrt(rng.uniform());
    const float phi = 6.28318530718f * rng.uniform();
    fx = float(x) + r * std::cos(phi);
    fy = float(y) + r * std::sin(phi);
}

/// The texel q of a neighbour point (rounded to nearest); false when it
/// falls off the W x H grid or on (x, y) itself.
ACC_HD inline bool neighbourTexel(float fx, float fy, std::uint32_t x, std::uint32_t y, std::uint32_t W, std::uint32_t H,
                                  std::size_t& q) {
    const long nx = std::lround(fx), ny = std::lround(fy);
    if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H) || (nx == long(x) && ny == long(y))) return false;
    q = std::size_t(ny) * W + std::size_t(nx);
    return true;
}

/// Spatial reuse's neighbour of texel (x, y) on a W x H grid: neighbourPoint
/// rounded by neighbourTexel. Draws two numbers whatever the outcome.
template <class RngT>
ACC_HD bool drawNeighbour(RngT& rng, float radius, std::uint32_t x, std::uint32_t y, std::uint32_t W, std::uint32_t H,
                          std::size_t& q) {
    float fx, fy;
    neighbourPoint(rng, radius, x, y, fx, fy);
    return neighbourTexel(fx, fy, x, y, W, H, q);
}

/// Temporal reuse's reprojection: the surface point where it was last frame
/// (`xPrev`: moved back by its particle's motion), projected with the
/// previous camera onto the previous lighting grid (W x H, `scale` x the
/// image). False behind the camera or off the grid; else its texel q and
/// its depth.
ACC_HD inline bool reprojectPoint(const Camera& prevCamera, const Vec3& xPrev, float scale, std::uint32_t W,
                                  std::uint32_t H, std::size_t& q, float& depth) {
    float fx, fy;
    if (!prevCamera.project(xPrev, fx, fy, depth)) return false;
    const float lx = fx * scale, ly = fy * scale;
    if (!(lx >= 0.0f && ly >= 0.0f && lx < float(W) && ly < float(H))) return false;
    q = std::size_t(ly) * W + std::size_t(lx);
    return true;
}

/// The history's M, capped at m_cap x the current M (at least 1), so an old
/// sample cannot outweigh the new ones without bound.
ACC_HD inline std::uint32_t capHistoryM(std::uint32_t historyM, std::uint32_t currentM, double mCap) {
    const double capped = std::floor(mCap * double(currentM > 1u ? currentM : 1u));
    return static_cast<std::uint32_t>(double(historyM) < capped ? double(historyM) : capped);
}

/// Combines the canonical reservoir (offer 0, in the current domain) with
/// the others (docs/MODEL.md section 4). none: W = w_sum / (M_total
/// p_hat(y)); basic: the sum of M runs only over the domains that could
/// have produced y; pairwise: each neighbour forms a two-strategy balance
/// heuristic with the canonical, whose confidence is split over the k pairs.
///
/// Domains d gives the offers and their domains:
///   std::uint32_t count();                     offers, 1..kMaxOffers
///   const StoredReservoir& reservoir(i);
///   float targetPdf(i, y);                     p_hat of light y in domain i (0: the current pixel)
///   bool supports(i, y);                       domain i could have produced y (basic)
///   void countTerm();                          a light term evaluated (the CPU's counters)
/// The weights, their order and the stream's draws are the CPU's and the
/// GPU's alike.
template <class Domains, class RngT>
ACC_HD StoredReservoir combineReservoirs(const Domains& d, BiasCorrection bias, RngT& rng) {
    const std::uint32_t n = d.count();
    const StoredReservoir& can = d.reservoir(0);
    if (n == 1) return can;
    double Mtotal = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) Mtotal += d.reservoir(i).M;

    // p_hat at the current pixel of every offered sample.
    float pc[kMaxOffers];
    pc[0] = can.W > 0.0f ? can.p_hat : 0.0f;
    for (std::uint32_t i = 1; i < n; ++i) {
        const StoredReservoir& r = d.reservoir(i);
        pc[i] = r.W > 0.0f ? d.targetPdf(0, r.y) : 0.0f;
        d.countTerm();
    }

    Reservoir out;
    StoredReservoir res;
    res.M = static_cast<std::uint32_t>(Mtotal < 4294967295.0 ? Mtotal : 4294967295.0);
    if (bias == BiasCorrection::pairwise) {
        const double k = n - 1;
        const double Mc = can.M;
        for (std::uint32_t i = 0; i < n; ++i) {
            const StoredReservoir& r = d.reservoir(i);
            double m = 0.0;
            if (r.W > 0.0f && pc[i] > 0.0f) {
                if (i == 0) {
                    for (std::uint32_t j = 1; j < n; ++j) {
                        const double pj = d.targetPdf(j, r.y);
                        d.countTerm();
                        m += resampling::pairwiseCanonicalTerm(d.reservoir(j).M, pj, Mc, k, pc[0], Mtotal);
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
        const StoredReservoir& r = d.reservoir(i);
        const float w = pc[i] * r.W * float(r.M);
        if (out.merge(r.y, w, pc[i], r.M, rng.uniform())) chosen = i;
    }
    if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
    double Z = Mtotal;
    if (bias == BiasCorrection::basic) {
        std::uint32_t M[kMaxOffers];
        std::uint8_t counts[kMaxOffers];
        for (std::uint32_t i = 0; i < n; ++i) {
            M[i] = d.reservoir(i).M;
            counts[i] = 0;
            if (i == chosen) continue;
            d.countTerm();
            counts[i] = d.supports(i, out.y) ? 1 : 0;
        }
        Z = resampling::basicNormalization(M, counts, n, chosen);
    }
    res.y = out.y;
    res.p_hat = out.p_hat;
    res.W = static_cast<float>(double(out.w_sum) / (Z * double(out.p_hat)));
    return res;
}

/// traceShadowRays's shade of the kept sample, whose light term t is
/// non-zero: Lr = f I G V W.
enum class Shade {
    lit,       ///< Lr written
    occluded,  ///< V = 0: with visibility reuse the stored reservoir becomes occludedReservoir()
    overflow,  ///< f I G W not finite: a zero sample (render.nonfinite decides on the reservoir)
};
ACC_HD inline Shade shadeSample(const LightTerm& t, float W, bool seen, Vec3& Lr) {
    if (!seen) return Shade::occluded;
    const Vec3 value = t.value * W;
    if (!(isFiniteNumber(value.x) && isFiniteNumber(value.y) && isFiniteNumber(value.z))) return Shade::overflow;
    Lr = value;
    return Shade::lit;
}

/// What visibility reuse keeps of an occluded sample for the next frame: its M, no sample.
ACC_HD inline StoredReservoir occludedReservoir(const StoredReservoir& r) { return StoredReservoir{kNoLight, 0.0f, r.M, 0.0f}; }

}  // namespace accretion::restir
