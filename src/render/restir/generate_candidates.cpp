// generateCandidates: the initial reservoir of each lighting texel.
#include "restir_pass.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/render/restir_steps.h"

namespace accretion::restir {
namespace {

template <ShadingModel SM, Primitive P, LightSource S, bool Count>
LightingCounters generateCandidatesKernel(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const std::uint32_t Mc = f.in.settings.render.candidates;
    PassCounters* pc = passCounters<Count>(f, Pass::generateCandidates);
    const std::uint32_t R = f.codec.bytes();
    const std::uint64_t seed = f.in.settings.render.seed;
    const float jitter = float(f.rs.regir_jitter);
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t tx, std::uint32_t ty, LightingCounters& c) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = StoredReservoir{};
        if (!g.hit()) return;
        rec.trip(Mc);
        // Per candidate its light's record, and the source's reads: an alias
        // entry, both children at every level of the tree, or an entry of a
        // tile or a ReGIR slot.
        constexpr bool presampled = S == LightSource::tiles || S == LightSource::regir;
        rec.read(Mc * (gpu_layout::kParticleRecord + (S == LightSource::power ? gpu_layout::kAliasEntry : 0u) +
                       (S == LightSource::tree ? 2u * gpu_layout::kLightTreeNode * f.in.lightTree->depth() : 0u) +
                       (presampled ? gpu_layout::kRisEntry : 0u)));
        rec.gather(Mc * (1u + (S == LightSource::power ? 1u : 0u) + (S == LightSource::tree ? f.in.lightTree->depth() : 0u) +
                         (presampled ? 1u : 0u)));
        rec.write(R);
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        Rng rng(px, f.in.frame, RngPass::restirCandidates, seed);
        // tiles: the pixel block's tile; regir: the receiver's jittered
        // cell, or outside the grid the tile (RTXDI's fallback).
        std::uint32_t tile = 0;
        std::int64_t cell = -1;
        if constexpr (presampled) tile = f.tiles->tileOf(tx, ty, f.lg.width, f.in.frame, seed);
        if constexpr (S == LightSource::regir) cell = f.regir->jitteredCell(sp.x, jitter, rng);
        const auto draw = [&](Rng& g) {
            if constexpr (S == LightSource::regir) return cell >= 0 ? f.regir->sample(std::uint32_t(cell), g) : f.tiles->sample(tile, g);
            else if constexpr (S == LightSource::tiles) return f.tiles->sample(tile, g);
            else return sampleCandidate<S>(f.L, f.in.powerTable, f.in.lightTree, sp, g);
        };
        // A ReGIR slot's pdf is 1 / W (W its unbiased 1 / p_src), so its
        // weight p_hat / pdf is p_hat W.
        const auto target = [&](std::uint32_t i) {
            ++c.lightTerms;
            return f.L.targetPdf<SM>(sp, i);
        };
        Reservoir r;
        if (!resampleCandidates(Mc, rng, draw, target, [&] { return f.reject(px, c); }, r)) return;  // out[px] stays empty
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

/// RIS of render.candidates lights from render.source (uniform, power, the
/// light tree, a light tile, a ReGIR cell) with target p_hat (no visibility);
/// with candidate_visibility, an occluded winner is dropped before reuse.
LightingCounters generateCandidates(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const LightSource source = f.in.settings.render.source;
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        switch (source) {
        case LightSource::power: return generateCandidatesKernel<SM, P, LightSource::power, Count>(f, out);
        case LightSource::tree: return generateCandidatesKernel<SM, P, LightSource::tree, Count>(f, out);
        case LightSource::tiles: return generateCandidatesKernel<SM, P, LightSource::tiles, Count>(f, out);
        case LightSource::regir: return generateCandidatesKernel<SM, P, LightSource::regir, Count>(f, out);
        case LightSource::uniform: break;
        }
        return generateCandidatesKernel<SM, P, LightSource::uniform, Count>(f, out);
    });
}

}  // namespace accretion::restir
