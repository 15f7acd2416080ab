#pragma once
// particle_split's CUDA kernels (split_kernels.cu): findNearLights and
// shadeParticlePixels; shadeSplitTexels traces its shadow rays in an OptiX
// raygen (programs.cu). Each reads the launch's params.
#include <cstddef>
#include <cstdint>

#include <cuda_runtime.h>

#include "launch_params.h"

namespace accretion::twin {

/// findNearLights: one thread per visible particle (p.split.params.visible).
void findNearLights(const LaunchParams& p, cudaStream_t stream);
/// far_new's select (shadeSplitTexels, before its ray launch): the device
/// arrays of `texels` entries each (temp: splitSelectTempBytes(texels)).
struct SplitSelectArrays {
    std::uint8_t* flags = nullptr;
    std::uint32_t *ids = nullptr, *count = nullptr;
    void* temp = nullptr;
    std::size_t tempBytes = 0;
};
std::size_t splitSelectTempBytes(std::size_t texels);
/// The texels without history (newSplitTexel), in order, into
/// p.split.newTexels; returns how many (read back: the ray launch's size,
/// OptiX has no indirect launch).
std::size_t selectNewSplitTexels(const LaunchParams& p, std::size_t texels, const SplitSelectArrays& a, cudaStream_t stream);
/// shadeSplitTexels' texels: one thread per texel (texels of them), its rays
/// (p.split.rays) summed in order, with last frame's (p.split.prevTexelLr) into p.split.texelLr.
void sumSplitTexels(const LaunchParams& p, std::size_t texels, cudaStream_t stream);
/// shadeParticlePixels: one thread per image pixel, its particle's texels interpolated.
void interpolateSplitPixels(const LaunchParams& p, cudaStream_t stream);

}  // namespace accretion::twin
