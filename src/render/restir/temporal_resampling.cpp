// temporalResampling: reuse of last frame's reservoir at the reprojected point.
#include "restir_pass.h"
#include "combine_reservoirs.h"

namespace accretion::restir {
namespace {

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters temporalResamplingKernel(const FrameContext& f, const std::vector<StoredReservoir>& cur,
                                    std::vector<StoredReservoir>& out) {
    const Restir::History& h = *f.prev;
    const Particles& particles = f.in.particles;
    PassCounters* pc = passCounters<Count>(f, Pass::temporalResampling);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c, Scratch& scratch) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = cur[px];
        if (!g.hit()) return;
        rec.trip();
        rec.read(R + 2 * gpu_layout::kParticleRecord);  // the reservoir, the particle now and before
        rec.gather(2);
        rec.write(R);
        // Where this surface point was: moved back by its particle's motion,
        // projected with the previous camera onto the previous lighting grid.
        const std::uint32_t j = g.particle;
        if (j >= h.particles.size()) {
            ++c.reuseRejected;
            return;
        }
        const Vec3 xPrev = h.particles.position[j] + g.local;  // frame-independent: relative to the particle
        float depth;
        std::size_t q = 0;
        bool ok = reprojectPoint(h.camera, xPrev, f.scale, h.gbuffer.width, h.gbuffer.height, q, depth);
        if (ok) {
            rec.read(gpu_layout::kGBufferTexel);
            const GBufferTexel& gp = h.gbuffer.texels[q];
            ok = gp.particle == j && resampling::similarSurface(g.normal, depth, gp.normal, gp.depth,
                                                                float(f.rs.normal_threshold), float(f.rs.depth_threshold));
        }
        if (!ok) {
            ++c.reuseRejected;
            return;
        }
        ++c.reuseAccepted;
        rec.read(R + gpu_layout::kParticleRecord);  // the previous reservoir and its light
        rec.gather(1);
        const ShadingPoint sp = shadingPoint(g, particles);
        std::vector<Offer>& offers = scratch.offers;
        offers.clear();
        offers.push_back({cur[px], {sp, &f.L, f.rs.candidate_visibility, &f.in.bvh}});
        StoredReservoir prev = h.reservoirs[q];
        prev.M = capHistoryM(prev.M, cur[px].M, f.rs.m_cap);
        // The previous frame's visibility needs the previous frame's BVH
        // (kept by the frame renderer when basic_visibility asks for it).
        offers.push_back({prev, {shadingPoint(h.gbuffer.texels[q], h.particles), &h.lights,
                                 f.rs.candidate_visibility || f.rs.visibility_reuse,
                                 f.in.previousBvh ? f.in.previousBvh : &f.in.bvh}});
        Rng rng(px, f.in.frame, RngPass::restirTemporal, f.in.settings.render.seed);
        out[px] = f.codec.roundTrip(f.sanitize(combineOffers<SM, P, Count>(scratch, f, rng, c, rec), px, c));
    });
}

}  // namespace

/// Reprojection through particle motion and the previous camera; rejection
/// on particle, normal and depth; history M capped at m_cap x M.
LightingCounters temporalResampling(const FrameContext& f, const std::vector<StoredReservoir>& cur, std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() { return temporalResamplingKernel<SM, P, Count>(f, cur, out); });
}

}  // namespace accretion::restir
