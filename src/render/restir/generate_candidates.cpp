// generateCandidates: the initial reservoir of each lighting texel, the body
// of restir_passes.h over the CPU's bridge and its candidate sources.
#include "cpu_bridge.h"

namespace accretion::restir {
namespace {

/// render.source on the CPU: uniform, power, the light tree at the receiver,
/// the texel block's light tile, or the receiver's jittered ReGIR cell (the
/// tile outside the grid, RTXDI's fallback).
template <LightSource S>
struct CpuSource {
    const FrameContext& f;
    static constexpr bool presampled = sourceInfo(S).presampled;

    /// Per candidate its light's record, and the source's reads: an alias
    /// entry, both children at every level of the tree, or an entry of a tile
    /// or a ReGIR slot.
    std::uint32_t reads() const {
        return gpu_layout::kParticleRecord + (S == LightSource::power ? gpu_layout::kAliasEntry : 0u) +
               (S == LightSource::tree ? 2u * gpu_layout::kLightTreeNode * f.in.lightTree->depth() : 0u) +
               (presampled ? gpu_layout::kRisEntry : 0u);
    }
    std::uint32_t gathers() const {
        return 1u + (S == LightSource::power ? 1u : 0u) + (S == LightSource::tree ? f.in.lightTree->depth() : 0u) + (presampled ? 1u : 0u);
    }

    struct NoMemo {};
    struct Drawer {
        const FrameContext& f;
        const ShadingPoint& sp;
        std::uint32_t tile;
        std::int64_t cell;
        /// tree: the receiver's descent importances, shared by its candidates.
        mutable std::conditional_t<S == LightSource::tree, LightTreeMemo, NoMemo> memo{};
        /// A ReGIR slot's pdf is 1 / W (W its unbiased 1 / p_src), so its
        /// weight p_hat / pdf is p_hat W.
        LightSample sample(Rng& g) const {
            if constexpr (S == LightSource::regir) return cell >= 0 ? f.regir->sample(std::uint32_t(cell), g) : f.tiles->sample(tile, g);
            else if constexpr (S == LightSource::tiles) return f.tiles->sample(tile, g);
            else if constexpr (S == LightSource::tree) return f.in.lightTree->sample(sp, g, memo);
            else return CandidateSampler<S>{f.L, f.in.powerTable, f.in.lightTree}.sample(sp, g);
        }
    };
    Drawer at(const ShadingPoint& sp, std::uint32_t x, std::uint32_t y, Rng& rng) const {
        std::uint32_t tile = 0;
        std::int64_t cell = -1;
        if constexpr (presampled)  // by the texel's place in the whole grid (a window's too)
            tile = f.tiles->tileOf(x + f.originX, y + f.originY, f.wholeWidth ? f.wholeWidth : f.lg.width, f.in.frame,
                                   f.in.settings.render.seed);
        if constexpr (sourceInfo(S).regirGrid) cell = f.regir->jitteredCell(sp.x, float(f.rs.regir_jitter), rng);
        return {f, sp, tile, cell};
    }
};

template <ShadingModel SM, Primitive P, LightSource S, bool Count>
LightingCounters generateCandidatesFrom(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const CpuSource<S> source{f};
    return forEachTexel<SM, P, Count>(f, Pass::generateCandidates, CpuBuffers{nullptr, &out},
                                      [&](auto& b, std::size_t px, std::uint32_t x, std::uint32_t y) {
                                          generateCandidatesTexel(b, source, px, x, y);
                                      });
}

}  // namespace

/// RIS of render.candidates lights from render.source (uniform, power, the
/// light tree, a light tile, a ReGIR cell) with target p_hat (no visibility);
/// with candidate_visibility, an occluded winner is dropped before reuse.
LightingCounters generateCandidates(const FrameContext& f, std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return withLightSource(f.in.settings.render.source,
                               [&]<LightSource S>() { return generateCandidatesFrom<SM, P, S, Count>(f, out); });
    });
}

}  // namespace accretion::restir
