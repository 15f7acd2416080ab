#pragma once
// The per-texel and per-pixel bodies of particle_restir (docs/MODEL.md
// section 4b), written once for the CPU and the GPU twin over the bridge of
// restir_passes.h. The lighting grid is the visible particles' billboard
// texels (particle_texels.h): generateCandidatesTexel and traceShadowRayTexel
// run on it as they are; temporal reuse finds a texel's history by its
// particle's id, spatial reuse draws its neighbours among the texels of the
// particles either side in world (Morton) order, and the pixels read their
// particle's texels at the end. A particle_restir bridge adds:
//
//   history: bool historyTexelOf(j, sub, q)  last frame's texel `sub` of particle j, if it was visible
//   pixels:  GBufferTexel pixel(px)           the image's G-buffer texel
//            std::uint32_t slotOf(j)           particle j's slot this frame
//            Vec2 pixelUv(g)                   the billboard uv of a pixel's receiver
//            GBufferTexel gridTexel(q), StoredReservoir gridReservoir(q), Vec3 gridLr(q)
//            void writePixelLr(px, Lr)
//   texel_history: Vec3 historyLr(q)         last frame's Lr of texel q (after its own average)
//
// In the pixel pass, texel(px), input(px) and recorder(px, g) are the
// pixel's, and the offers combine with bias correction basic (there is no
// canonical sample at the pixel for pairwise MIS to weigh against).
#include "accretion/render/particle_texels.h"
#include "accretion/render/restir_passes.h"

namespace accretion::restir {

/// The most texels a pixel resamples: the four bilinear texels of each of
/// up to 16 layers (restir.texel_rays), plus its own empty canonical reservoir.
inline constexpr std::uint32_t kMaxPixelOffers = 65;
static_assert(kMaxPixelOffers <= kMaxOffers, "the pixel's offers fit combineReservoirs' arrays");

/// particle_restir's temporalResampling at texel px: last frame's reservoir
/// of the same texel of the same particle (no reprojection: the id is the
/// history), its M capped at m_cap x M, combined with this frame's
/// (restir.bias_correction). Refused only when the particle was not visible.
template <class B>
ACC_HD_BODY void temporalByIdTexel(B& b, std::size_t px) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto&& rec = b.recorder(px, g);
    const StoredReservoir cur = b.input(px);
    b.output(px, cur);
    if (!g.hit()) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip();
    rec.read(R + gpu_layout::kParticleRecord + 4);  // the reservoir, the particle, its previous slot
    rec.gather(2);
    rec.write(R);
    std::size_t q = 0;
    if (!b.historyTexelOf(g.particle, std::uint32_t(px % p.texelsPerParticle()), q)) {
        b.reuse(ReuseOutcome::noHistory);
        return;
    }
    b.reuse(ReuseOutcome::sameParticle);
    rec.read(R + gpu_layout::kGBufferTexel + gpu_layout::kParticleRecord);  // the previous reservoir, texel and light
    rec.gather(1);
    combineWithHistory(b, px, g, cur, q);
}

/// The texel of particle_restir's spatial neighbour s of texel px: a slot
/// uniform among the world_neighbours either side (the texel's own among
/// them: its other texels), a texel of its layer uniform on that billboard.
/// Draws two numbers. False when it drew px itself.
template <class RngT>
ACC_HD bool drawWorldNeighbour(RngT& rng, const ReuseParams& p, std::size_t px, std::size_t& q) {
    const std::uint32_t per = p.texelsPerParticle(), perLayer = p.texelSide * p.texelSide;
    const std::uint32_t slot = std::uint32_t(px / per), layer = std::uint32_t(px % per) / perLayer;
    const std::uint32_t lo = slot > p.worldNeighbours ? slot - p.worldNeighbours : 0u;
    const std::uint32_t hi = slot + p.worldNeighbours < p.visible ? slot + p.worldNeighbours : p.visible - 1;
    const std::uint32_t span = hi - lo + 1;
    std::uint32_t v = lo + std::uint32_t(rng.uniform() * float(span));
    if (v > hi) v = hi;
    std::uint32_t s = std::uint32_t(rng.uniform() * float(perLayer));
    if (s >= perLayer) s = perLayer - 1;
    q = std::size_t(v) * per + layer * perLayer + s;
    return q != px;
}

/// particle_restir's spatialResampling at texel px, iteration `iteration`:
/// restir.spatial_neighbours texels drawn by drawWorldNeighbour, refused on
/// normal alone (the depth test is the screen's), combined with this
/// texel's reservoir (restir.bias_correction).
template <class B>
ACC_HD_BODY void spatialWorldTexel(B& b, std::size_t px, std::uint32_t iteration) {
    const ReuseParams& p = b.params();
    resampleNeighbours(
        b, px, iteration, [&](typename B::Rng& rng, std::size_t& q) { return drawWorldNeighbour(rng, p, px, q); },
        [&](const GBufferTexel& g, const GBufferTexel& gn) {
            return glm::dot(g.normal, gn.normal) < p.normalThreshold ? ReuseOutcome::normal
                   : gn.particle == g.particle                         ? ReuseOutcome::sameParticle
                                                                       : ReuseOutcome::otherParticle;
        });
}

/// traceShadowRays's last step with restir.texel_history h: texel px's Lr
/// becomes (1 - h) x this frame's + h x its own last frame's (the same
/// texel of the same particle), an exponential average over frames. Reads
/// gridLr(px), writes writeLr(px).
template <class B>
ACC_HD_BODY void accumulateTexelLr(B& b, std::size_t px) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    if (!g.hit()) return;
    auto&& rec = b.recorder(px, g);
    std::size_t q = 0;
    if (!b.historyTexelOf(g.particle, std::uint32_t(px % p.texelsPerParticle()), q)) return;
    rec.read(4 + gpu_layout::kRadiance);
    rec.gather(1);
    b.writeLr(px, (1.0f - p.texelHistory) * b.gridLr(px) + p.texelHistory * b.historyLr(q));
}

/// The texels pixel g reads and their weights: the bilinear four (one for
/// 1x1) of each layer, weights summing to 1 over all of them. Returns how many.
template <class B>
ACC_HD std::uint32_t pixelTexels(const B& b, const GBufferTexel& g, std::size_t q[kMaxPixelOffers], float w[kMaxPixelOffers]) {
    const ReuseParams& p = b.params();
    return texelStencil(b.pixelUv(g), p.texelSide, p.texelLayers, std::size_t(b.slotOf(g.particle)) * p.texelsPerParticle(), q, w);
}

/// shadeParticlePixels' and resampleParticlePixels' start at pixel px showing g: Lr = 0 written, and
/// for a hit the texels it reads (pixelTexels); returns how many (0 on a miss).
template <class B, class Rec>
ACC_HD_BODY std::uint32_t beginPixel(B& b, std::size_t px, const GBufferTexel& g, Rec& rec, std::size_t q[kMaxPixelOffers],
                                     float w[kMaxPixelOffers]) {
    b.writePixelLr(px, Vec3(0.0f));
    rec.write(gpu_layout::kRadiance);
    return g.hit() ? pixelTexels(b, g, q, w) : 0u;
}

/// shadeParticlePixels (restir.pixel_shading interpolate): the pixel's Lr is its particle's
/// texels' Lr, bilinear at its uv and averaged over the layers (biased: the
/// light at the texels, not at the pixel's point).
template <class B>
ACC_HD_BODY void interpolatePixel(B& b, std::size_t px) {
    const GBufferTexel g = b.pixel(px);
    auto&& rec = b.recorder(px, g);
    std::size_t q[kMaxPixelOffers];
    float w[kMaxPixelOffers];
    const std::uint32_t n = beginPixel(b, px, g, rec, q, w);
    if (n == 0) return;
    rec.read(4 + n * gpu_layout::kRadiance);  // the slot, the texels' Lr
    rec.gather(1);
    Vec3 Lr(0.0f);
    for (std::uint32_t k = 0; k < n; ++k) Lr += w[k] * b.gridLr(q[k]);
    b.writePixelLr(px, Lr);
}

/// resampleParticlePixels (restir.pixel_shading resample): the pixel resamples the samples of its
/// particle's texels (those interpolate would read) at its own point, each
/// weighed p_hat_pixel(y) W M, normalised by the M of the texels whose own
/// target could produce the kept sample (basic), and traces its own shadow
/// ray: unbiased wherever the texels' reservoirs are.
template <class B>
ACC_HD_BODY void resamplePixel(B& b, std::size_t px) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.pixel(px);
    auto&& rec = b.recorder(px, g);
    std::size_t q[kMaxPixelOffers];
    float w[kMaxPixelOffers];
    const std::uint32_t n = beginPixel(b, px, g, rec, q, w);
    if (n == 0) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip(n);
    rec.read(4 + n * (R + gpu_layout::kGBufferTexel + gpu_layout::kParticleRecord));
    rec.gather(1 + n);
    auto offers = b.template offers<kMaxPixelOffers>();
    offers.addCurrent(StoredReservoir{}, g);  // the pixel's domain, no sample of its own
    for (std::uint32_t k = 0; k < n; ++k) offers.addCurrent(b.gridReservoir(q[k]), b.gridTexel(q[k]));
    typename B::Rng rng(p.pixelKey(px) ^ (std::uint64_t(1) << 61), p.frame, RngPass::restirSpatial, p.seed);
    const StoredReservoir r = sanitizeReservoir(offers.combine(rng), [&] { return b.reject(px); });
    if (!(r.W > 0.0f)) return;
    rec.read(gpu_layout::kParticleRecord);
    if constexpr (std::decay_t<decltype(rec)>::on) rec.hint(b.clusterOf(r.y));
    Shade shade;
    Vec3 Lr(0.0f);
    if (!shadeKeptSample(b, b.shadingPoint(g), r, rec, shade, Lr)) return;
    switch (shade) {
    case Shade::lit: b.writePixelLr(px, Lr); break;
    case Shade::occluded: b.occluded(); break;
    case Shade::overflow: b.reject(px); break;
    }
}

}  // namespace accretion::restir
