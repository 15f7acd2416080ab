// particle_split's CUDA kernels: particle_split_passes.h's bodies over the
// twin's bridge (split_device.h). The launches' errors are checked by the
// caller (cudaGetLastError after the pass); far_new's select checks its
// CUB and copy calls itself.
#include "split_kernels.h"

#include <cub/device/device_select.cuh>

#include "cuda_error.h"
#include "split_device.h"

namespace accretion::twin {
namespace {

__global__ void findNearLightsKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t v = blockIdx.x * blockDim.x + threadIdx.x;
    if (v >= p.split.params.visible) return;
    SplitBridge<ShadingModel::isotropic> b(p);  // no light term: the model does not matter
    psplit::findNearLightsOf(b, v);
}

__global__ void markNewSplitTexelsKernel(const __grid_constant__ LaunchParams p, std::size_t texels, std::uint8_t* flags,
                                         std::uint32_t* ids) {
    const std::size_t q = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (q >= texels) return;
    SplitBridge<ShadingModel::isotropic> b(p);  // no light term: the model does not matter
    flags[q] = psplit::newSplitTexel(b, q);
    ids[q] = std::uint32_t(q);
}

__global__ void sumSplitTexelsKernel(const __grid_constant__ LaunchParams p, std::size_t texels) {
    const std::size_t q = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
    if (q >= texels) return;
    SplitBridge<ShadingModel::isotropic> b(p);  // no light term: the model does not matter
    psplit::sumSplitTexel(b, q);
}

__global__ void interpolateSplitPixelsKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= p.camera.width || y >= p.camera.height) return;
    SplitBridge<ShadingModel::isotropic> b(p);
    psplit::interpolateSplitPixel(b, std::size_t(y) * p.camera.width + x);
}

}  // namespace

void findNearLights(const LaunchParams& p, cudaStream_t stream) {
    const std::uint32_t n = p.split.params.visible;
    if (n) findNearLightsKernel<<<(n + 127) / 128, 128, 0, stream>>>(p);
}

std::size_t splitSelectTempBytes(std::size_t texels) {
    std::size_t bytes = 0;
    CUDA_CHECK(cub::DeviceSelect::Flagged(nullptr, bytes, static_cast<std::uint32_t*>(nullptr), static_cast<std::uint8_t*>(nullptr),
                                          static_cast<std::uint32_t*>(nullptr), static_cast<std::uint32_t*>(nullptr), int(texels)));
    return bytes;
}

std::size_t selectNewSplitTexels(const LaunchParams& p, std::size_t texels, const SplitSelectArrays& a, cudaStream_t stream) {
    if (texels == 0) return 0;
    markNewSplitTexelsKernel<<<unsigned((texels + 127) / 128), 128, 0, stream>>>(p, texels, a.flags, a.ids);
    std::size_t bytes = a.tempBytes;
    CUDA_CHECK(cub::DeviceSelect::Flagged(a.temp, bytes, a.ids, a.flags, p.split.newTexels, a.count, int(texels), stream));
    std::uint32_t fresh = 0;
    CUDA_CHECK(cudaMemcpyAsync(&fresh, a.count, sizeof fresh, cudaMemcpyDeviceToHost, stream));
    CUDA_CHECK(cudaStreamSynchronize(stream));
    return fresh;
}

void sumSplitTexels(const LaunchParams& p, std::size_t texels, cudaStream_t stream) {
    if (texels) sumSplitTexelsKernel<<<unsigned((texels + 127) / 128), 128, 0, stream>>>(p, texels);
}

void interpolateSplitPixels(const LaunchParams& p, cudaStream_t stream) {
    const dim3 group(8, 8), blocks((p.camera.width + 7) / 8, (p.camera.height + 7) / 8);
    interpolateSplitPixelsKernel<<<blocks, group, 0, stream>>>(p);
}

}  // namespace accretion::twin
