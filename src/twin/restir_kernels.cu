#include "restir_kernels.h"

#include "accretion/render/upsample_pixel.h"
#include "device_bridge.h"
#include "restir_device.h"

namespace accretion::twin {
namespace {

/// The thread's texel of the lighting grid.
__device__ inline bool pixelOf(const LaunchParams& p, std::uint32_t& x, std::uint32_t& y, std::size_t& px) {
    x = blockIdx.x * blockDim.x + threadIdx.x;
    y = blockIdx.y * blockDim.y + threadIdx.y;
    px = std::size_t(y) * p.restir.reuse.width + x;
    return x < p.restir.reuse.width && y < p.restir.reuse.height;
}

/// body(bridge, px, x, y) on the thread's texel of the lighting grid, if it
/// has one, through the device bridge.
template <ShadingModel SM, class Body>
__device__ inline void onTexel(const LaunchParams& p, Body&& body) {
    std::uint32_t x, y;
    std::size_t px;
    if (!pixelOf(p, x, y, px)) return;
    DeviceBridge<SM> b(p);
    body(b, px, x, y);
}

// The restir passes: launches of restir_passes.h's bodies. The bridge keeps
// a reference to the launch's parameters: __grid_constant__ lets it point
// into the parameter space, where a plain by-value parameter whose address
// is taken is copied to every thread's local memory (temporalResampling at
// 1080p on the H200: 0.84 ms with the copy, against 0.09 ms before the bridge).
template <ShadingModel SM>
__global__ void generateCandidatesKernel(const __grid_constant__ LaunchParams p) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t x, std::uint32_t y) {
        restir::generateCandidatesTexel(b, DeviceSource{p}, px, x, y);
    });
}

template <ShadingModel SM>
__global__ void temporalResamplingKernel(const __grid_constant__ LaunchParams p) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { restir::temporalResamplingTexel(b, px); });
}

template <ShadingModel SM>
__global__ void spatialResamplingKernel(const __grid_constant__ LaunchParams p, std::uint32_t iteration) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t x, std::uint32_t y) {
        restir::spatialResamplingTexel(b, px, x, y, iteration);
    });
}

// particle_restir's own passes (particle_restir_passes.h), on the texels.
template <ShadingModel SM>
__global__ void temporalByIdKernel(const __grid_constant__ LaunchParams p) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { restir::temporalByIdTexel(b, px); });
}

template <ShadingModel SM>
__global__ void spatialWorldKernel(const __grid_constant__ LaunchParams p, std::uint32_t iteration) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { restir::spatialWorldTexel(b, px, iteration); });
}

template <ShadingModel SM>
__global__ void accumulateTexelLrKernel(const __grid_constant__ LaunchParams p) {
    onTexel<SM>(p, [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { restir::accumulateTexelLr(b, px); });
}

/// shadeParticlePixels (restir.pixel_shading interpolate): one thread per image pixel.
template <ShadingModel SM>
__global__ void interpolatePixelsKernel(const __grid_constant__ LaunchParams p) {
    const std::uint32_t x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= p.camera.width || y >= p.camera.height) return;
    DeviceBridge<SM> b(p);
    restir::interpolatePixel(b, std::size_t(y) * p.camera.width + x);
}

dim3 blocks(const LaunchParams& p) { return dim3((p.restir.reuse.width + 7) / 8, (p.restir.reuse.height + 7) / 8); }
const dim3 kGroup(8, 8);

/// launch.template operator()<SM>() with the frame's shading model.
template <class Launch>
void byModel(ShadingModel model, Launch&& launch) {
    switch (model) {
    case ShadingModel::lambert: launch.template operator()<ShadingModel::lambert>(); break;
    case ShadingModel::sphere: launch.template operator()<ShadingModel::sphere>(); break;
    case ShadingModel::isotropic: launch.template operator()<ShadingModel::isotropic>(); break;
    }
}

/// The lighting grid's G-buffer: each texel the image pixel containing its centre.
__global__ void reduceGBufferKernel(LaunchParams p, GBufferTexel* grid) {
    std::uint32_t x, y;
    std::size_t px;
    if (!pixelOf(p, x, y, px)) return;
    std::uint32_t fx, fy;
    reducedTexelSource(x, y, p.restir.reuse.scale, p.camera.width, p.camera.height, fx, fy);
    grid[px] = p.gbuffer[std::size_t(fy) * p.camera.width + fx];
}

/// upsampleLighting: Lr of every image pixel from the lighting grid's.
__global__ void upsampleLightingKernel(LaunchParams p) {
    const std::uint32_t x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= p.camera.width || y >= p.camera.height) return;
    const std::size_t px = std::size_t(y) * p.camera.width + x;
    const RestirParams& rp = p.restir;
    p.Lr[px] = upsamplePixel(p.gbuffer[px], x, y, rp.reuse.scale, rp.gbuffer, rp.reuse.width, rp.reuse.height, rp.Lr, p.albedo,
                             rp.reuse.normalThreshold, rp.reuse.depthThreshold);
}

}  // namespace

void reduceGBuffer(const LaunchParams& p, GBufferTexel* grid, cudaStream_t stream) {
    reduceGBufferKernel<<<blocks(p), kGroup, 0, stream>>>(p, grid);
}

void upsampleLighting(const LaunchParams& p, cudaStream_t stream) {
    const dim3 b((p.camera.width + 7) / 8, (p.camera.height + 7) / 8);
    upsampleLightingKernel<<<b, kGroup, 0, stream>>>(p);
}

void generateCandidates(const LaunchParams& p, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { generateCandidatesKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p); });
}

void temporalResampling(const LaunchParams& p, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { temporalResamplingKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p); });
}

void temporalResamplingById(const LaunchParams& p, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { temporalByIdKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p); });
}

void resampleWorldNeighbours(const LaunchParams& p, std::uint32_t iteration, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { spatialWorldKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p, iteration); });
}

void accumulateTexelLr(const LaunchParams& p, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { accumulateTexelLrKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p); });
}

void interpolatePixels(const LaunchParams& p, cudaStream_t stream) {
    const dim3 b((p.camera.width + 7) / 8, (p.camera.height + 7) / 8);
    byModel(p.model, [&]<ShadingModel SM>() { interpolatePixelsKernel<SM><<<b, kGroup, 0, stream>>>(p); });
}

void spatialResampling(const LaunchParams& p, std::uint32_t iteration, cudaStream_t stream) {
    byModel(p.model, [&]<ShadingModel SM>() { spatialResamplingKernel<SM><<<blocks(p), kGroup, 0, stream>>>(p, iteration); });
}

}  // namespace accretion::twin
