#pragma once
// The per-texel bodies of ReSTIR DI's reuse passes (docs/MODEL.md section 4),
// written once for the CPU and the GPU twin, as RTXDI writes its resampling
// functions once over its RAB_* bridge. A body reads the frame, records what
// one GPU thread does, and writes its output only through a bridge B:
//
//   using Rng                                the pixel streams (Rng on the CPU, PortableRng on
//                                            the GPU: the same numbers)
//   const ReuseParams& params()              the pass's settings and grid
//   GBufferTexel texel(px)                   this frame's lighting-grid texel
//   StoredReservoir input(px)                the pass's input reservoir
//   void output(px, r)                       the pass's output, as it is
//   void store(px, r)                        a combined reservoir: sanitized (render.nonfinite)
//                                            and stored as the frame keeps reservoirs
//   Rec recorder(px, g)                      the thread's counters (Recorder<Count> on the CPU,
//                                            NoRecorder on the GPU), its branch key recorded
//   std::uint32_t reservoirBytes()           a stored reservoir's bytes (the codec's)
//   void reuse(bool accepted)                an offered history or neighbour kept or rejected
//   Offers offers<N>()                       an empty list of at most N offers:
//                                              addCurrent(r, g)  a reservoir of this frame at texel g
//                                              addHistory(r, q)  last frame's reservoir at its texel q
//                                              combine(rng)      restir_steps.h's combineReservoirs
//   history: bool historyHas(j), Vec3 historyPosition(j), const Camera& historyCamera(),
//            GBufferTexel historyTexel(q), StoredReservoir historyReservoir(q)
//
// The CPU's bridge is src/render/restir/cpu_bridge.h (Embree, counters, the
// reservoir codec), the twin's src/twin/device_bridge.h (OptiX, nothing
// counted). tests/twin/shared_core_check.cu runs these bodies on the GPU and
// on the CPU through one bridge of its own and compares them bit for bit.
#include <cstddef>
#include <cstdint>

#include "accretion/core/rng.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/render/restir_steps.h"

namespace accretion::restir {

/// What the reuse passes read of the settings and the lighting grid.
struct ReuseParams {
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
    std::uint32_t width = 0, height = 0;  ///< the lighting grid (this frame's and the history's)
    float scale = 1.0f;                   ///< lighting / image resolution
    float normalThreshold = 0.9f, depthThreshold = 0.1f;
    double mCap = 20.0;                   ///< restir.m_cap
    std::uint32_t neighbours = 0;         ///< restir.spatial_neighbours
    float radius = 1.0f;                  ///< spatial disc radius in lighting texels (>= 1)
};

/// The counters of a thread that counts nothing (the GPU's bridge).
struct NoRecorder {
    ACC_HD void trip(std::uint32_t = 1) {}
    ACC_HD void read(std::uint32_t) {}
    ACC_HD void gather(std::uint32_t) {}
    ACC_HD void write(std::uint32_t) {}
};

/// temporalResampling at texel px: the surface point where it was last frame
/// (moved back by its particle's motion), projected with the previous camera
/// onto the previous lighting grid; rejected on another particle, normal or
/// depth; the history's M capped at m_cap x M; combined with this frame's
/// reservoir (restir.bias_correction).
template <class B>
ACC_HD void temporalResamplingTexel(B& b, std::size_t px) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto rec = b.recorder(px, g);
    const StoredReservoir cur = b.input(px);
    b.output(px, cur);
    if (!g.hit()) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip();
    rec.read(R + 2 * gpu_layout::kParticleRecord);  // the reservoir, the particle now and before
    rec.gather(2);
    rec.write(R);
    const std::uint32_t j = g.particle;
    if (!b.historyHas(j)) {
        b.reuse(false);
        return;
    }
    const Vec3 xPrev = b.historyPosition(j) + g.local;  // frame-independent: relative to the particle
    float depth;
    std::size_t q = 0;
    bool ok = reprojectPoint(b.historyCamera(), xPrev, p.scale, p.width, p.height, q, depth);
    if (ok) {
        rec.read(gpu_layout::kGBufferTexel);
        const GBufferTexel gp = b.historyTexel(q);
        ok = gp.particle == j && resampling::similarSurface(g.normal, depth, gp.normal, gp.depth, p.normalThreshold, p.depthThreshold);
    }
    if (!ok) {
        b.reuse(false);
        return;
    }
    b.reuse(true);
    rec.read(R + gpu_layout::kParticleRecord);  // the previous reservoir and its light
    rec.gather(1);
    auto offers = b.template offers<2>();
    offers.addCurrent(cur, g);
    StoredReservoir prev = b.historyReservoir(q);
    prev.M = capHistoryM(prev.M, cur.M, p.mCap);
    offers.addHistory(prev, q);
    typename B::Rng rng(px, p.frame, RngPass::restirTemporal, p.seed);
    b.store(px, offers.combine(rng));
}

/// spatialResampling at texel (x, y) = px, iteration `iteration`: k
/// neighbours uniform in a disc of the radius (drawNeighbour), rejected off
/// the grid, on a miss, or on normal and depth; combined with this texel's
/// reservoir (restir.bias_correction).
template <class B>
ACC_HD void spatialResamplingTexel(B& b, std::size_t px, std::uint32_t x, std::uint32_t y, std::uint32_t iteration) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto rec = b.recorder(px, g);
    b.output(px, b.input(px));
    if (!g.hit()) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip(p.neighbours);
    rec.read(R + gpu_layout::kParticleRecord);
    rec.gather(1);
    rec.write(R);
    typename B::Rng rng(px ^ (std::uint64_t(iteration) << 40), p.frame, RngPass::restirSpatial, p.seed);
    auto offers = b.template offers<kMaxOffers>();
    offers.addCurrent(b.input(px), g);
    for (std::uint32_t s = 0; s < p.neighbours; ++s) {
        std::size_t q;
        if (!drawNeighbour(rng, p.radius, x, y, p.width, p.height, q)) {
            b.reuse(false);
            continue;
        }
        const GBufferTexel gn = b.texel(q);
        rec.read(gpu_layout::kGBufferTexel);
        if (!gn.hit() || !resampling::similarSurface(g.normal, g.depth, gn.normal, gn.depth, p.normalThreshold, p.depthThreshold)) {
            b.reuse(false);
            continue;
        }
        b.reuse(true);
        rec.read(R + gpu_layout::kParticleRecord);
        rec.gather(1);
        offers.addCurrent(b.input(q), gn);
    }
    b.store(px, offers.combine(rng));
}

}  // namespace accretion::restir
