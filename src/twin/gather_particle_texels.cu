#include "gather_particle_texels.h"

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_select.cuh>

#include <algorithm>

#include "cuda_error.h"

namespace accretion::twin {
namespace {

__global__ void markVisibleKernel(const GBufferTexel* gbuffer, std::size_t pixels, std::uint8_t* flags) {
    const std::size_t px = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (px >= pixels) return;
    const std::uint32_t j = gbuffer[px].particle;
    if (j != kNoParticle) flags[j] = 1;
}

__global__ void iotaKernel(std::uint32_t* ids, std::uint32_t n) {
    const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) ids[i] = i;
}

__global__ void mortonKeysKernel(const Vec3* position, const std::uint32_t* ids, std::uint32_t n, MortonFrame frame,
                                 std::uint64_t* keys) {
    const std::uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) keys[k] = frame.key(position[ids[k]]);
}

__global__ void writeSlotsKernel(const std::uint32_t* sortedIds, std::uint32_t n, std::uint32_t* slotOf) {
    const std::uint32_t v = blockIdx.x * blockDim.x + threadIdx.x;
    if (v < n) slotOf[sortedIds[v]] = v;
}

/// One thread per texel of the grid (its tail too: misses).
__global__ void writeTexelsKernel(const LaunchParams p, const std::uint32_t* sortedIds, std::uint32_t visible, std::uint32_t side,
                                  std::uint32_t layers, const TexelPointRule points, std::size_t gridTexels, GBufferTexel* texels) {
    const std::size_t t = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (t >= gridTexels) return;
    const std::uint32_t perLayer = side * side, per = perLayer * layers;
    if (t >= std::size_t(visible) * per) {
        texels[t] = GBufferTexel{};
        return;
    }
    const std::uint32_t j = sortedIds[t / per], s = std::uint32_t(t % per) % perLayer;
    texels[t] = billboardPointTexel(p.camera, j, p.position[j], p.radius[j], p.frames[j],
                                    texelPointUv(j, s, side, points), p.model);
}

unsigned groups(std::size_t n) { return unsigned((n + 255) / 256); }

}  // namespace

std::size_t gatherTempBytes(std::uint32_t n) {
    std::size_t selectBytes = 0, sortBytes = 0;
    CUDA_CHECK(cub::DeviceSelect::Flagged(nullptr, selectBytes, static_cast<std::uint32_t*>(nullptr), static_cast<std::uint8_t*>(nullptr),
                                          static_cast<std::uint32_t*>(nullptr), static_cast<std::uint32_t*>(nullptr), int(n)));
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, sortBytes, static_cast<std::uint64_t*>(nullptr), static_cast<std::uint64_t*>(nullptr),
                                               static_cast<std::uint32_t*>(nullptr), static_cast<std::uint32_t*>(nullptr), int(n), 0, 63));
    return std::max(selectBytes, sortBytes);
}

std::uint32_t findVisibleParticles(const LaunchParams& p, const MortonFrame& frame, const GatherArrays& a, cudaStream_t stream) {
    const std::uint32_t n = p.particleCount;
    const std::size_t pixels = std::size_t(p.camera.width) * p.camera.height;
    if (n == 0) return 0;
    CUDA_CHECK(cudaMemsetAsync(a.flags, 0, n, stream));
    markVisibleKernel<<<groups(pixels), 256, 0, stream>>>(p.gbuffer, pixels, a.flags);
    iotaKernel<<<groups(n), 256, 0, stream>>>(a.sortedIds, n);

    // The visible ids, in id order.
    std::size_t bytes = a.tempBytes;
    CUDA_CHECK(cub::DeviceSelect::Flagged(a.temp, bytes, a.sortedIds, a.flags, a.ids, a.count, int(n), stream));
    std::uint32_t visible = 0;
    CUDA_CHECK(cudaMemcpyAsync(&visible, a.count, sizeof visible, cudaMemcpyDeviceToHost, stream));
    CUDA_CHECK(cudaStreamSynchronize(stream));

    CUDA_CHECK(cudaMemsetAsync(a.slotOf, 0xff, n * sizeof(std::uint32_t), stream));
    if (visible == 0) return 0;
    // Morton order, ties by id: the radix sort is stable and its input in id order.
    mortonKeysKernel<<<groups(visible), 256, 0, stream>>>(p.position, a.ids, visible, frame, a.keys);
    bytes = a.tempBytes;
    CUDA_CHECK(cub::DeviceRadixSort::SortPairs(a.temp, bytes, a.keys, a.sortedKeys, a.ids, a.sortedIds, int(visible), 0, 63, stream));
    writeSlotsKernel<<<groups(visible), 256, 0, stream>>>(a.sortedIds, visible, a.slotOf);
    CUDA_CHECK(cudaGetLastError());
    return visible;
}

void writeParticleTexels(const LaunchParams& p, const std::uint32_t* sortedIds, std::uint32_t visible, std::uint32_t side,
                         std::uint32_t layers, const TexelPointRule& points, std::size_t gridTexels, GBufferTexel* texels,
                         cudaStream_t stream) {
    writeTexelsKernel<<<groups(gridTexels), 256, 0, stream>>>(p, sortedIds, visible, side, layers, points, gridTexels, texels);
    CUDA_CHECK(cudaGetLastError());
}

}  // namespace accretion::twin
