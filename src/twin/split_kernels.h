#pragma once
// particle_split's CUDA kernels (split_kernels.cu): findNearLights and
// shadeParticlePixels; shadeSplitTexels traces its shadow rays in an OptiX
// raygen (programs.cu). Each reads the launch's params.
#include <cuda_runtime.h>

#include "launch_params.h"

namespace accretion::twin {

/// findNearLights: one thread per visible particle (p.split.params.visible).
void findNearLights(const LaunchParams& p, cudaStream_t stream);
/// shadeSplitTexels' texels: one thread per texel (texels of them), its rays
/// (p.split.rays) summed in order, with last frame's (p.split.prevTexelLr) into p.split.texelLr.
void sumSplitTexels(const LaunchParams& p, std::size_t texels, cudaStream_t stream);
/// shadeParticlePixels: one thread per image pixel, its particle's texels interpolated.
void interpolateSplitPixels(const LaunchParams& p, cudaStream_t stream);

}  // namespace accretion::twin
