// spatialResampling: reuse of k neighbours' reservoirs in a disc of pixels.
#include "restir_pass.h"
#include "combine_reservoirs.h"

namespace accretion::restir {
namespace {

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters spatialResamplingKernel(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                   std::vector<StoredReservoir>& out) {
    const std::uint32_t W = f.lg.width, H = f.lg.height;
    const float radius = std::max(1.0f, float(f.rs.spatial_radius) * f.scale);
    const std::uint32_t k = f.rs.spatial_neighbours;
    PassCounters* pc = passCounters<Count>(f, Pass::spatialResampling);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(W, H, [&](std::size_t px, std::uint32_t x, std::uint32_t y, LightingCounters& c, Scratch& scratch) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = cur[px];
        if (!g.hit()) return;
        rec.trip(k);
        rec.read(R + gpu_layout::kParticleRecord);
        rec.gather(1);
        rec.write(R);
        Rng rng(px ^ (std::uint64_t(iteration) << 40), f.in.frame, RngPass::restirSpatial, f.in.settings.render.seed);
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        std::vector<Offer>& offers = scratch.offers;
        offers.clear();
        // With temporal reuse as well, a temporal output also holds samples
        // that passed the previous frame's test, not this pixel's: treating it
        // as tested here is then an approximation (measured by `accretion
        // bias`); exact with temporal off.
        const bool tested = f.rs.candidate_visibility;
        offers.push_back({cur[px], {sp, &f.L, tested, &f.in.bvh}});
        for (std::uint32_t s = 0; s < k; ++s) {
            std::size_t q;
            if (!drawNeighbour(rng, radius, x, y, W, H, q)) {
                ++c.reuseRejected;
                continue;
            }
            const GBufferTexel& gn = f.lg.texels[q];
            rec.read(gpu_layout::kGBufferTexel);
            if (!gn.hit() || !resampling::similarSurface(g.normal, g.depth, gn.normal, gn.depth,
                                                         float(f.rs.normal_threshold), float(f.rs.depth_threshold))) {
                ++c.reuseRejected;
                continue;
            }
            ++c.reuseAccepted;
            rec.read(R + gpu_layout::kParticleRecord);
            rec.gather(1);
            offers.push_back({cur[q], {shadingPoint(gn, f.in.particles), &f.L, tested, &f.in.bvh}});
        }
        out[px] = f.codec.roundTrip(f.sanitize(combineOffers<SM, P, Count>(scratch, f, rng, c, rec), px, c));
    });
}

}  // namespace

/// k neighbours uniform in a disc of spatial_radius (scaled to the lighting
/// grid); iteration seeds the pass's streams.
LightingCounters spatialResampling(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                   std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() { return spatialResamplingKernel<SM, P, Count>(f, iteration, cur, out); });
}

}  // namespace accretion::restir
