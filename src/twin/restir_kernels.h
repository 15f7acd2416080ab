#pragma once
// The twin's restir passes that trace no ray, as CUDA kernels in 8x8 blocks
// (generateCandidates, temporalResampling, spatialResampling, and the
// reduction and upsampling of reduced-resolution lighting); the shadow
// rays are OptiX raygens (programs.cu). Each reads the launch's params.
#include <cuda_runtime.h>

#include "launch_params.h"

namespace accretion::twin {

void generateCandidates(const LaunchParams& p, cudaStream_t stream);
void temporalResampling(const LaunchParams& p, cudaStream_t stream);
void spatialResampling(const LaunchParams& p, std::uint32_t iteration, cudaStream_t stream);
/// particle_restir on the texels (p.restir's grid): temporal reuse by id,
/// spatial reuse among world neighbours, restir.texel_history's average;
/// and shadeParticlePixels' interpolation over the image (resample is the
/// raygen resampleParticlePixels: it traces).
void temporalResamplingById(const LaunchParams& p, cudaStream_t stream);
void resampleWorldNeighbours(const LaunchParams& p, std::uint32_t iteration, cudaStream_t stream);
void accumulateTexelLr(const LaunchParams& p, cudaStream_t stream);
void interpolatePixels(const LaunchParams& p, cudaStream_t stream);
/// restir.resolution_scale < 1: the lighting grid's G-buffer from the image's
/// (p.restir.reuse.width x height texels into `grid`), and upsampleLighting (the
/// CPU's bilateral rule, upsamplePixel) from p.restir.Lr into p.Lr.
void reduceGBuffer(const LaunchParams& p, GBufferTexel* grid, cudaStream_t stream);
void upsampleLighting(const LaunchParams& p, cudaStream_t stream);

}  // namespace accretion::twin
