#pragma once
// Where seed 004's voxel radiance cache lies and which of its cells the
// particles reach: host code the CPU's VoxelCache and the twin share.
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/geometry/camera.h"
#include "accretion/particles/particles.h"
#include "accretion/render/voxel_cache_passes.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Where the voxel cache's grid lies, in world coordinates (the frames'
/// origins move with the camera; the grid and its history do not): placed
/// over the first frame's particles, each with its reach
/// (voxel::particleReach), and 5% of the longest side around them, cubic
/// cells of longest side / voxel.cells. The twin places its grid here too.
struct VoxelPlacement {
    DVec3 lower{0.0};
    double cellSize = 0.0;
    std::uint32_t nx = 0, ny = 0, nz = 0;
    bool placed() const { return cellSize > 0.0; }
    std::uint64_t cells() const { return std::uint64_t(nx) * ny * nz; }
    /// The grid in the coordinates of a frame whose origin is `origin`.
    voxel::VoxelGrid inFrame(const Vec3& origin) const;
    /// Whether every particle's reach (frame coordinates + origin) lies inside.
    bool holds(const Particles& particles, const Vec3& origin) const;
};

/// The placement over `particles` (frame coordinates + origin), `cells`
/// along the longest side. Throws InputError (naming voxel.cells) above
/// kMaxVoxelCells cells.
VoxelPlacement placeVoxelGrid(const Particles& particles, const Vec3& origin, std::uint32_t cells);
inline constexpr std::uint64_t kMaxVoxelCells = std::uint64_t(1) << 25;  ///< 2 GiB of cells

/// The cells some particle's reach covers: those updateVoxelCache updates
/// (1) and empties (0). The same for every view: the cache is the world's.
std::vector<std::uint8_t> occupiedCells(const voxel::VoxelGrid& grid, const Particles& particles);
/// The stores of that marking (a thread per particle storing each cell of
/// its reach, x fastest) as warps of `warpSize` consecutive particles issue
/// them: per store, the distinct 32-byte sectors of its lanes, summed over
/// the stores and the warps (updateVoxelCache's item steps).
std::uint64_t markingSectorSteps(const voxel::VoxelGrid& grid, const Particles& particles, std::uint32_t warpSize);

/// The frame's VoxelParams (the grid in its coordinates, the settings, the
/// camera): the CPU and the twin both make theirs here.
voxel::VoxelParams voxelParams(const Settings& s, const VoxelPlacement& placement, const Vec3& origin, const Camera& camera,
                               std::uint32_t frame, std::uint64_t seed);

}  // namespace accretion
