// shadeSplitTexels: every texel of the grid, particle_split_passes.h's body
// over the CPU's bridge. Counted as the twin runs it: with far_new, a select
// of the texels without history; a thread per ray of each texel (a launch
// of the texels by their rays, then far_new's extra rays of the selected
// texels), then a kernel per texel summing them.
#include "cpu_split_bridge.h"

namespace accretion::psplit {

LightingCounters shadeSplitTexels(const CpuFrame& f) {
    const std::size_t texels = f.texels.grid.texels.size();
    // far_new: each texel's place among those without history, in order.
    const std::uint32_t extra = extraNewRays(f.params);
    std::size_t fresh = 0;
    f.newIndex.assign(extra ? texels : 0, kNoSlot);
    if (extra) {
        std::vector<std::uint8_t> isNew(texels, 0);
        forEachItem(f, texels, nullptr, [&isNew](auto& b, std::size_t q) { isNew[q] = newSplitTexel(b, q); });
        for (std::size_t q = 0; q < texels; ++q)
            if (isNew[q]) f.newIndex[q] = std::uint32_t(fresh++);
    }
    PassCounters* pc = nullptr;
    if (f.in.counters) {
        const std::size_t threads = texels * raysPerTexel(f.params) + fresh * extra;
        pc = extra ? &f.in.counters->add(Pass::shadeSplitTexels, std::uint32_t(threads), 1)
                   : &f.in.counters->add(Pass::shadeSplitTexels, std::uint32_t(texels), raysPerTexel(f.params));
        pc->dispatches = extra ? 3 : 2;
    }
    const bool countSelect = extra && pc;
    return forEachItem(f, texels, pc, [countSelect](auto& b, std::size_t q) {
        if (countSelect) newSplitTexel(b, q);  // counting: the select's reads, record q's as the sum's
        sumSplitTexel(b, q);
    });
}

}  // namespace accretion::psplit
