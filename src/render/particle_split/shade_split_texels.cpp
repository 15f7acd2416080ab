// shadeSplitTexels: every texel of the grid, particle_split_passes.h's body
// over the CPU's bridge. Counted as the twin runs it: a thread per ray of
// each texel (a launch of the texels by their rays), then a kernel per
// texel summing them.
#include "cpu_split_bridge.h"

namespace accretion::psplit {

LightingCounters shadeSplitTexels(const CpuFrame& f) {
    const GBuffer& grid = f.texels.grid;
    const std::size_t texels = grid.texels.size();
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::shadeSplitTexels, std::uint32_t(texels), raysPerTexel(f.params)) : nullptr;
    if (pc) pc->dispatches = 2;
    return forEachItem(f, texels, pc, [](auto& b, std::size_t q) { sumSplitTexel(b, q); });
}

}  // namespace accretion::psplit
