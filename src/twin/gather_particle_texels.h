#pragma once
// particle_restir's gatherParticleTexels on the twin: the CPU's rule
// (particle_texels.h) with CUB's select and radix sort. Raw device
// pointers: the host side (twin_main.cpp) owns the buffers.
#include <cstddef>
#include <cstdint>

#include <cuda_runtime.h>

#include "accretion/render/particle_texels.h"
#include "launch_params.h"

namespace accretion::twin {

/// The gather's device arrays, n = p.particleCount entries each (temp: gatherTempBytes(n)).
struct GatherArrays {
    std::uint8_t* flags = nullptr;
    std::uint32_t *ids = nullptr, *sortedIds = nullptr, *count = nullptr, *slotOf = nullptr;
    std::uint64_t *keys = nullptr, *sortedKeys = nullptr;
    void* temp = nullptr;
    std::size_t tempBytes = 0;
};

/// The scratch bytes CUB's select and sort of n particles need.
std::size_t gatherTempBytes(std::uint32_t n);

/// The visible particles of p.gbuffer in Morton order of `frame` (ties by
/// id) into a.sortedIds, their slots into a.slotOf (kNoSlot elsewhere).
/// Returns how many (read back: the grid's launch size; an engine would
/// dispatch the later passes indirectly).
std::uint32_t findVisibleParticles(const LaunchParams& p, const MortonFrame& frame, const GatherArrays& a, cudaStream_t stream);

/// Their texels (side x side x layers each, kTexelRowWidth a row, the last
/// row's tail missing, where `points` puts them): `gridTexels` of them into `texels`.
void writeParticleTexels(const LaunchParams& p, const std::uint32_t* sortedIds, std::uint32_t visible, std::uint32_t side,
                         std::uint32_t layers, const TexelPointRule& points, std::size_t gridTexels, GBufferTexel* texels,
                         cudaStream_t stream);

}  // namespace accretion::twin
