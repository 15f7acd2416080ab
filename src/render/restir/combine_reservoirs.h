#pragma once
// Combining reservoirs on the CPU: the shared step (restir_steps.h) over the
// offers of a pass, with the CPU's counters and, for basic_visibility, its
// shadow rays.
#include "accretion/render/restir_steps.h"
#include "../cpu_passes.h"
#include "restir_pass.h"

namespace accretion::restir {

/// The offers of a CPU pass as restir_steps.h's Domains: each domain's
/// p_hat from its own lights, the light terms counted, and basic's support
/// test tracing the domain's frame when basic_visibility asks for it.
template <ShadingModel SM, Primitive P, bool Count>
struct CpuDomains {
    const std::vector<Offer>& offers;
    const RestirSettings& rs;
    const VisibilityOptions& vis;
    bool shadows;
    LightingCounters& c;
    Recorder<Count>& rec;

    std::uint32_t count() const { return static_cast<std::uint32_t>(offers.size()); }
    const StoredReservoir& reservoir(std::uint32_t i) const { return offers[i].r; }
    float targetPdf(std::uint32_t i, std::uint32_t y) const {
        return offers[i].domain.lights->template targetPdf<SM>(offers[i].domain.sp, y);
    }
    void countTerm() const { ++c.lightTerms; }
    bool supports(std::uint32_t i, std::uint32_t y) const {
        const Domain& d = offers[i].domain;
        LightTerm t;
        if (!d.lights->template term<SM>(d.sp, y, t) || !(luminance(t.value) > 0.0f)) return false;
        if (!(rs.basic_visibility && d.visibilityTested && shadows)) return true;
        const bool seen = countedShadowRay<P>(*d.bvh, vis, *d.lights, d.sp, y, t, c, rec);
        if (!seen) ++c.shadowOccluded;
        return seen;
    }
};

/// restir_steps.h's combineReservoirs over a CPU pass's offers (scratch.offers).
template <ShadingModel SM, Primitive P, bool Count>
StoredReservoir combineOffers(const Scratch& scratch, const FrameContext& f, Rng& rng, LightingCounters& c,
                              Recorder<Count>& rec) {
    const CpuDomains<SM, P, Count> domains{scratch.offers, f.rs, f.vis, f.shadows, c, rec};
    return combineReservoirs(domains, f.rs.bias_correction, rng);
}

}  // namespace accretion::restir
