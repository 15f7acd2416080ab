#pragma once
// The voxel cache's CUDA kernels (voxel_kernels.cu): the cells the
// particles reach, and shadeVoxelPixels; updateVoxelCache traces its
// shadow rays in an OptiX raygen (programs.cu). Each reads the launch's params.
#include <cstdint>

#include <cuda_runtime.h>

#include "launch_params.h"

namespace accretion::twin {

/// The cells some particle's reach covers (the CPU's occupiedCells) into
/// p.voxel.occupied (cleared first: count cells).
void markVoxelCells(const LaunchParams& p, std::uint8_t* occupied, std::uint32_t count, cudaStream_t stream);
/// updateVoxelCache's cells: one thread per cell, its rays (p.voxel.rays)
/// summed in order, averaged with last frame's (p.voxel.read) into p.voxel.write.
void sumVoxelRays(const LaunchParams& p, cudaStream_t stream);
/// shadeVoxelPixels: one thread per image pixel, reading p.voxel.read.
void shadeVoxelPixels(const LaunchParams& p, cudaStream_t stream);

}  // namespace accretion::twin
