#pragma once
#include <cstdint>
#include <span>

#include <nlohmann/json.hpp>

#include "accretion/scene/settings.h"

namespace accretion {

/// BLAS memory of a frame's clusters (docs/MODEL.md section 6): a GPU estimate
/// from bytes per triangle and per internal node, under one allocation per
/// BLAS (blas_alignment) against a pooled buffer (pool_alignment), and
/// after compaction; Embree's own figure for comparison.
struct BlasMemory {
    std::uint64_t clusters = 0;
    std::uint64_t triangles = 0;
    std::uint64_t gpuBytes = 0;          ///< sum of the BLAS sizes, unaligned
    std::uint64_t perBlasAllocBytes = 0; ///< each BLAS its own allocation
    std::uint64_t pooledBytes = 0;       ///< all BLAS in one pool
    std::uint64_t compactedPooledBytes = 0;
    std::int64_t embreeBytes = 0;        ///< Embree's memory monitor after the build (whole scene)
    double perBlasWaste() const { return perBlasAllocBytes ? 1.0 - double(gpuBytes) / double(perBlasAllocBytes) : 0.0; }
    double pooledWaste() const { return pooledBytes ? 1.0 - double(gpuBytes) / double(pooledBytes) : 0.0; }
};

/// The one JSON form of BLAS memory (`accretion cost`'s memory sweep and
/// its GPU report): byte counts end in _bytes, waste is a fraction.
nlohmann::json toJson(const BlasMemory& memory);

/// The GPU estimate of one BLAS of `triangles` primitives.
std::uint64_t gpuBlasBytes(std::uint64_t triangles, const GpuSettings& gpu);

/// BLAS memory of clusters of the given triangle counts.
BlasMemory blasMemory(std::span<const std::uint32_t> trianglesPerCluster, const GpuSettings& gpu, std::int64_t embreeBytes);

}  // namespace accretion
