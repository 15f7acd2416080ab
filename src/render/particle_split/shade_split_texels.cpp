// shadeSplitTexels: every texel of the grid, particle_split_passes.h's body
// over the CPU's bridge.
#include "cpu_split_bridge.h"

namespace accretion::psplit {

LightingCounters shadeSplitTexels(const CpuFrame& f) {
    const GBuffer& grid = f.texels.grid;
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::shadeSplitTexels, grid.width, grid.height) : nullptr;
    return forEachItem(f, grid.texels.size(), pc, [](auto& b, std::size_t q) { sumSplitTexel(b, q); });
}

}  // namespace accretion::psplit
