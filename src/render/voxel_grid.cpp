#include "accretion/render/voxel_grid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <vector>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "accretion/core/error.h"

namespace accretion {

voxel::VoxelGrid VoxelPlacement::inFrame(const Vec3& origin) const {
    voxel::VoxelGrid g;
    g.lower = Vec3(lower - DVec3(origin));
    g.cellSize = float(cellSize);
    g.invCellSize = float(1.0 / cellSize);
    g.nx = nx;
    g.ny = ny;
    g.nz = nz;
    return g;
}

bool VoxelPlacement::holds(const Particles& particles, const Vec3& origin) const {
    if (!placed()) return false;
    const DVec3 upper = lower + cellSize * DVec3(nx, ny, nz);
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const DVec3 p = DVec3(particles.position[i]) + DVec3(origin);
        const double r = voxel::particleReach(particles.radius[i]);
        for (int k = 0; k < 3; ++k)
            if (!(p[k] - r >= lower[k] && p[k] + r <= upper[k])) return false;
    }
    return true;
}

VoxelPlacement placeVoxelGrid(const Particles& particles, const Vec3& origin, std::uint32_t cells) {
    DVec3 lo(std::numeric_limits<double>::max()), hi(std::numeric_limits<double>::lowest());
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const DVec3 p = DVec3(particles.position[i]) + DVec3(origin);
        const double r = voxel::particleReach(particles.radius[i]);
        lo = glm::min(lo, p - r);
        hi = glm::max(hi, p + r);
    }
    if (particles.size() == 0) lo = hi = DVec3(origin);
    const DVec3 extent = hi - lo;
    const double longest = std::max({extent.x, extent.y, extent.z, 1e-6});
    const double margin = 0.05 * longest;
    VoxelPlacement v;
    v.cellSize = (longest + 2.0 * margin) / double(cells);
    std::uint32_t n[3];
    for (int k = 0; k < 3; ++k) {
        const double side = extent[k] + 2.0 * margin;
        n[k] = std::max<std::uint32_t>(1u, std::uint32_t(std::ceil(side / v.cellSize - 1e-9)));
        v.lower[k] = lo[k] - margin - 0.5 * (double(n[k]) * v.cellSize - side);  // centred
    }
    v.nx = n[0];
    v.ny = n[1];
    v.nz = n[2];
    if (v.cells() > kMaxVoxelCells)
        throw InputError(fmt::format("voxel.cells = {}: the particles' bounds need {}x{}x{} = {} cells, more than {} ({} MiB)", cells,
                                     v.nx, v.ny, v.nz, v.cells(), kMaxVoxelCells,
                                     kMaxVoxelCells * sizeof(voxel::VoxelCell) >> 20));
    return v;
}

std::vector<std::uint8_t> occupiedCells(const voxel::VoxelGrid& grid, const Particles& particles) {
    std::vector<std::uint8_t> occupied(grid.count(), 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, particles.size(), 4096), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::uint32_t lo[3], hi[3];
            grid.reach(particles.position[i], voxel::particleReach(particles.radius[i]), lo, hi);
            for (std::uint32_t z = lo[2]; z <= hi[2]; ++z)
                for (std::uint32_t y = lo[1]; y <= hi[1]; ++y)
                    for (std::uint32_t x = lo[0]; x <= hi[0]; ++x)
                        std::atomic_ref<std::uint8_t>(occupied[grid.index(x, y, z)]).store(1, std::memory_order_relaxed);
        }
    });
    return occupied;
}

namespace {
/// One marking thread's cells: the box lo + [0, n) per axis, stored x fastest.
struct ReachBox {
    std::uint32_t lo[3], n[3];
    std::uint64_t stores() const { return std::uint64_t(n[0]) * n[1] * n[2]; }
    /// The cell of its k-th store.
    std::uint32_t cell(const voxel::VoxelGrid& g, std::uint64_t k) const {
        return g.index(lo[0] + std::uint32_t(k % n[0]), lo[1] + std::uint32_t(k / n[0] % n[1]),
                       lo[2] + std::uint32_t(k / (std::uint64_t(n[0]) * n[1])));
    }
};
}  // namespace

std::uint64_t markingSectorSteps(const voxel::VoxelGrid& grid, const Particles& particles, std::uint32_t warpSize) {
    const std::size_t warps = (particles.size() + warpSize - 1) / warpSize;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, warps, 64), std::uint64_t(0),
        [&](const auto& r, std::uint64_t steps) {
            std::vector<ReachBox> lanes;
            std::vector<std::uint32_t> sectors;
            for (std::size_t w = r.begin(); w != r.end(); ++w) {
                lanes.clear();
                std::uint64_t most = 0;
                for (std::size_t i = w * warpSize; i < std::min(particles.size(), (w + 1) * warpSize); ++i) {
                    std::uint32_t lo[3], hi[3];
                    grid.reach(particles.position[i], voxel::particleReach(particles.radius[i]), lo, hi);
                    lanes.push_back({{lo[0], lo[1], lo[2]}, {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1}});
                    most = std::max(most, lanes.back().stores());
                }
                for (std::uint64_t k = 0; k < most; ++k) {  // the warp's k-th store: the lanes that have one
                    sectors.clear();
                    for (const ReachBox& l : lanes)
                        if (k < l.stores()) sectors.push_back(l.cell(grid, k) / 32u);  // a 32-byte sector of byte flags
                    std::sort(sectors.begin(), sectors.end());
                    steps += std::uint64_t(std::unique(sectors.begin(), sectors.end()) - sectors.begin());
                }
            }
            return steps;
        },
        std::plus<>());
}

voxel::VoxelParams voxelParams(const Settings& s, const VoxelPlacement& placement, const Vec3& origin, const Camera& camera,
                               std::uint32_t frame, std::uint64_t seed) {
    voxel::VoxelParams p;
    p.grid = placement.inFrame(origin);
    p.rays = s.voxel.rays;
    p.history = float(s.voxel.history);
    const double clamp = s.voxel.near_clamp * placement.cellSize;
    p.nearClamp2 = float(clamp * clamp);
    p.basis = s.voxel.basis;
    p.frame = frame;
    p.seed = seed;
    p.camera = camera.position;
    p.facesPlane = s.geometry.orientation == Orientation::view_plane;
    p.planeNormal = -camera.forward;
    return p;
}

}  // namespace accretion
