// particle_split's CUDA kernels: particle_split_passes.h's bodies over the
// twin's bridge (split_device.h). Errors are checked by the caller
// (cudaGetLastError after the pass).
#include "split_device.h"
#include "split_kernels.h"

namespace accretion::twin {
namespace {

__global__ void findNearLightsKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t v = blockIdx.x * blockDim.x + threadIdx.x;
    if (v >= p.split.params.visible) return;
    SplitBridge<ShadingModel::isotropic> b(p);  // no light term: the model does not matter
    psplit::findNearLightsOf(b, v);
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

void sumSplitTexels(const LaunchParams& p, std::size_t texels, cudaStream_t stream) {
    if (texels) sumSplitTexelsKernel<<<unsigned((texels + 127) / 128), 128, 0, stream>>>(p, texels);
}

void interpolateSplitPixels(const LaunchParams& p, cudaStream_t stream) {
    const dim3 group(8, 8), blocks((p.camera.width + 7) / 8, (p.camera.height + 7) / 8);
    interpolateSplitPixelsKernel<<<blocks, group, 0, stream>>>(p);
}

}  // namespace accretion::twin
