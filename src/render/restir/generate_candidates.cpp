// generateCandidates: the initial reservoir of each lighting texel.
#include "restir_pass.h"
#include "accretion/lighting/light_sampler.h"

namespace accretion::restir {
namespace {

template <ShadingModel SM, Primitive P, bool Power, bool Count>
LightingCounters generateCandidatesKernel(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const std::uint32_t Mc = f.in.settings.render.candidates;
    PassCounters* pc = passCounters<Count>(f, pass::generateCandidates);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = StoredReservoir{};
        if (!g.hit()) return;
        rec.trip(Mc);
        rec.read(Mc * (gpu_layout::kParticleRecord + (Power ? gpu_layout::kAliasEntry : 0u)));
        rec.write(R);
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        Rng rng(px, f.in.frame, RngPass::restirCandidates, f.in.settings.render.seed);
        Reservoir r;
        bool discard = false;
        for (std::uint32_t m = 0; m < Mc; ++m) {
            const LightSample x = sampleSource<Power>(f.L, f.in.powerTable, rng);
            float p_hat = f.L.targetPdf<SM>(sp, x.i);
            float w = p_hat / x.pdf;
            ++c.lightTerms;
            if (!std::isfinite(w) || !std::isfinite(p_hat)) {  // render.nonfinite: a zero candidate, or no reservoir
                discard = f.reject(px, c) || discard;
                w = p_hat = 0.0f;
            }
            r.update(x.i, w, p_hat, rng.uniform());
        }
        r.finalize();
        if (!std::isfinite(r.w_sum) || !std::isfinite(r.W)) {  // finite weights whose sum overflowed
            discard = f.reject(px, c) || discard;
            r.W = 0.0f;
        }
        if (discard) return;  // out[px] stays empty
        if (f.rs.candidate_visibility && f.shadows && r.W > 0.0f) {
            // Bitterli et al. 2020, Alg. 5: drop an occluded candidate before reuse.
            LightTerm t;
            if (f.L.term<SM>(sp, r.y, t)) {
                ++c.shadowRays;
                RayCounters rc;
                const bool seen = visible<P>(f.in.bvh, f.vis, sp, r.y, f.L.packed[r.y].position, f.L.packed[r.y].radius, t, rec.rayCounters(rc));
                rec.ray(rc);
                if (!seen) {
                    ++c.shadowOccluded;
                    r.W = 0.0f;
                }
            }
        }
        out[px] = f.codec.roundTrip(StoredReservoir::of(r));
    });
}

}  // namespace

/// RIS of render.candidates lights from the source pmf (uniform, or power
/// when the plan built a power table) with target p_hat (no visibility);
/// with candidate_visibility, an occluded winner is dropped before reuse.
LightingCounters generateCandidates(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const bool power = f.in.powerTable != nullptr;
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return power ? generateCandidatesKernel<SM, P, true, Count>(f, out) : generateCandidatesKernel<SM, P, false, Count>(f, out);
    });
}

}  // namespace accretion::restir
