#pragma once
// Combining reservoirs: the step temporalResampling and spatialResampling
// share (docs/MODEL.md section 4). The MIS weights are the pure functions
// of lighting/resampling.h.
#include <algorithm>

#include "accretion/lighting/resampling.h"
#include "restir_pass.h"

namespace accretion::restir {

/// Combines the canonical reservoir (offers[0], in the current domain) with
/// the others. none: W = w_sum / (M_total p_hat(y)); basic: the sum of M runs
/// only over domains whose p_hat of y is non-zero (and that see y, with
/// basic_visibility); pairwise: each neighbour forms a two-strategy balance
/// heuristic with the canonical, whose confidence is split over the k pairs.
template <ShadingModel SM, Primitive P, bool Count>
StoredReservoir combineReservoirs(Scratch& scratch, const LightArrays& L, const RestirSettings& rs,
                                  const VisibilityOptions& vis, bool shadows, Rng& rng, LightingCounters& c,
                                  Recorder<Count>& rec) {
    const std::vector<Offer>& offers = scratch.offers;
    const auto n = static_cast<std::uint32_t>(offers.size());
    const Offer& can = offers[0];
    const ShadingPoint& sp = can.domain.sp;
    if (n == 1) return can.r;
    double Mtotal = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) Mtotal += offers[i].r.M;

    // p_hat at the current pixel of every offered sample.
    std::vector<float>& pc = scratch.pc;
    pc.resize(n);
    pc[0] = can.r.W > 0.0f ? can.r.p_hat : 0.0f;
    for (std::uint32_t i = 1; i < n; ++i) {
        pc[i] = offers[i].r.W > 0.0f ? L.targetPdf<SM>(sp, offers[i].r.y) : 0.0f;
        ++c.lightTerms;
    }

    Reservoir out;
    if (rs.bias_correction == BiasCorrection::pairwise) {
        const double k = n - 1;
        const double Mc = can.r.M;
        for (std::uint32_t i = 0; i < n; ++i) {
            const StoredReservoir& r = offers[i].r;
            double m = 0.0;
            if (r.W > 0.0f && pc[i] > 0.0f) {
                if (i == 0) {
                    for (std::uint32_t j = 1; j < n; ++j) {
                        const double pj = offers[j].domain.lights->targetPdf<SM>(offers[j].domain.sp, r.y);
                        ++c.lightTerms;
                        m += resampling::pairwiseCanonicalTerm(offers[j].r.M, pj, Mc, k, pc[0], Mtotal);
                    }
                } else {
                    m = resampling::pairwiseNeighbourWeight(r.M, r.p_hat, Mc, k, pc[i], Mtotal);
                }
            }
            const float w = static_cast<float>(m * double(pc[i]) * double(r.W));
            out.merge(r.y, w, pc[i], r.M, rng.uniform());
        }
        StoredReservoir res;
        res.M = static_cast<std::uint32_t>(std::min(Mtotal, 4294967295.0));
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
    StoredReservoir res;
    res.M = static_cast<std::uint32_t>(std::min(Mtotal, 4294967295.0));
    if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
    double Z = Mtotal;
    if (rs.bias_correction == BiasCorrection::basic) {
        // Which other domains could have produced y (and, with basic_visibility, see it).
        scratch.M.resize(n);
        scratch.counts.assign(n, 0);
        for (std::uint32_t i = 0; i < n; ++i) {
            scratch.M[i] = offers[i].r.M;
            if (i == chosen) continue;
            const Domain& d = offers[i].domain;
            LightTerm t;
            ++c.lightTerms;
            if (!d.lights->term<SM>(d.sp, out.y, t) || !(luminance(t.value) > 0.0f)) continue;
            if (rs.basic_visibility && d.visibilityTested && shadows) {
                ++c.shadowRays;
                RayCounters rc;
                const PackedLight& l = d.lights->packed[out.y];
                const bool seen = visible<P>(*d.bvh, vis, d.sp, out.y, l.position, l.radius, t, rec.rayCounters(rc));
                rec.ray(rc);
                if (!seen) {
                    ++c.shadowOccluded;
                    continue;
                }
            }
            scratch.counts[i] = 1;
        }
        Z = resampling::basicNormalization(scratch.M, scratch.counts, chosen);
    }
    res.y = out.y;
    res.p_hat = out.p_hat;
    res.W = static_cast<float>(double(out.w_sum) / (Z * double(out.p_hat)));
    return res;
}

}  // namespace accretion::restir
