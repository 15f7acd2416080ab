// The voxel cache's CUDA kernels: voxel_cache_passes.h's bodies and the
// grid's stencils over the twin's bridge (voxel_device.h). Errors are
// checked by the caller (cudaGetLastError after the pass).
#include "voxel_device.h"
#include "voxel_kernels.h"

namespace accretion::twin {
namespace {

/// One thread per particle: every cell of its reach marked (a byte store of
/// 1: threads that share a cell write the same value).
__global__ void markVoxelCellsKernel(const __grid_constant__ LaunchParams p, std::uint8_t* occupied) {
    const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= p.particleCount) return;
    const voxel::VoxelGrid& g = p.voxel.params.grid;
    std::uint32_t lo[3], hi[3];
    g.reach(p.position[i], voxel::particleReach(p.radius[i]), lo, hi);
    for (std::uint32_t z = lo[2]; z <= hi[2]; ++z)
        for (std::uint32_t y = lo[1]; y <= hi[1]; ++y)
            for (std::uint32_t x = lo[0]; x <= hi[0]; ++x) occupied[g.index(x, y, z)] = 1;
}

__global__ void sumVoxelRaysKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t c = blockIdx.x * blockDim.x + threadIdx.x;
    if (c >= p.voxel.params.grid.count()) return;
    VoxelBridge<> b(p);
    voxel::updateVoxelCell(b, c);
}

template <ShadingModel SM>
__global__ void shadeVoxelPixelsKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= p.camera.width || y >= p.camera.height) return;
    VoxelBridge<> b(p);
    voxel::shadeVoxelPixel<SM>(b, std::size_t(y) * p.camera.width + x);
}

}  // namespace

void markVoxelCells(const LaunchParams& p, std::uint8_t* occupied, std::uint32_t count, cudaStream_t stream) {
    cudaMemsetAsync(occupied, 0, count, stream);
    if (p.particleCount) markVoxelCellsKernel<<<(p.particleCount + 255) / 256, 256, 0, stream>>>(p, occupied);
}

void sumVoxelRays(const LaunchParams& p, cudaStream_t stream) {
    const std::uint32_t cells = p.voxel.params.grid.count();
    sumVoxelRaysKernel<<<(cells + 255) / 256, 256, 0, stream>>>(p);
}

void shadeVoxelPixels(const LaunchParams& p, cudaStream_t stream) {
    const dim3 group(8, 8), blocks((p.camera.width + 7) / 8, (p.camera.height + 7) / 8);
    switch (p.model) {
    case ShadingModel::lambert: shadeVoxelPixelsKernel<ShadingModel::lambert><<<blocks, group, 0, stream>>>(p); break;
    case ShadingModel::sphere: shadeVoxelPixelsKernel<ShadingModel::sphere><<<blocks, group, 0, stream>>>(p); break;
    case ShadingModel::isotropic: shadeVoxelPixelsKernel<ShadingModel::isotropic><<<blocks, group, 0, stream>>>(p); break;
    }
}

}  // namespace accretion::twin
