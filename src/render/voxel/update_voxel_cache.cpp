// updateVoxelCache: every cell of the grid, voxel_cache_passes.h's body over
// the CPU's bridge (an unoccupied cell is emptied).
#include "cpu_voxel_bridge.h"

namespace accretion::voxel {

LightingCounters updateVoxelCache(const CpuFrame& f) {
    const VoxelGrid& g = f.params.grid;
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::updateVoxelCache, g.nx, g.ny * g.nz) : nullptr;
    return dispatchVoxel(f, [&]<Primitive P, bool Count>() {
        return forEachItem<P, Count>(f, g.count(), pc, [](auto& b, std::size_t c) { updateVoxelCell(b, std::uint32_t(c)); });
    });
}

}  // namespace accretion::voxel
