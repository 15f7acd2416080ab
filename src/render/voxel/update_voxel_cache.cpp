// updateVoxelCache: every cell of the grid, voxel_cache_passes.h's body over
// the CPU's bridge (an unoccupied cell is emptied). Counted as the twin runs
// it: the occupied cells marked, a thread per particle storing each cell of
// its reach (the record's item steps: its warps' stores, a step per 32-byte
// sector, markingSectorSteps), a thread per ray of each cell (its grid: launch x = cell x *
// rays + ray, y = the cell's row), then a kernel per cell summing them.
#include "accretion/render/voxel_grid.h"
#include "cpu_voxel_bridge.h"

namespace accretion::voxel {

LightingCounters updateVoxelCache(const CpuFrame& f) {
    const VoxelGrid& g = f.params.grid;
    const std::uint32_t rays = std::max(1u, f.params.rays);
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::updateVoxelCache, g.nx * rays, g.ny * g.nz) : nullptr;
    if (pc) {
        pc->dispatches = 3;  // the cells marked, their rays, the sums
        pc->itemSteps = markingSectorSteps(g, f.in.particles, f.in.settings.gpu.warp_size);  // the marking
    }
    return dispatchVoxel(f, [&]<Primitive P, bool Count>() {
        return forEachItem<P, Count>(f, g.count(), pc, [](auto& b, std::size_t c) { updateVoxelCell(b, std::uint32_t(c)); }, rays);
    });
}

}  // namespace accretion::voxel
