#include "accretion/gpu/gpu_memory.h"

#include <cmath>

namespace accretion {
namespace {

std::uint64_t alignUp(std::uint64_t bytes, std::uint64_t alignment) {
    return (bytes + alignment - 1) / alignment * alignment;
}

}  // namespace

std::uint64_t gpuBlasBytes(std::uint64_t triangles, const GpuSettings& gpu) {
    // A BVH of branching factor w over t leaves has ceil((t - 1) / (w - 1)) internal nodes (at least the root).
    const std::uint64_t nodes = triangles > 1 ? (triangles - 1 + gpu.bvh_width - 2) / (gpu.bvh_width - 1) : 1;
    return static_cast<std::uint64_t>(std::ceil(double(triangles) * gpu.blas_bytes_per_triangle +
                                                double(nodes) * gpu.blas_bytes_per_node));
}

BlasMemory blasMemory(std::span<const std::uint32_t> trianglesPerCluster, const GpuSettings& gpu, std::int64_t embreeBytes) {
    BlasMemory m;
    m.embreeBytes = embreeBytes;
    for (std::uint32_t t : trianglesPerCluster) {
        const std::uint64_t b = gpuBlasBytes(t, gpu);
        ++m.clusters;
        m.triangles += t;
        m.gpuBytes += b;
        m.perBlasAllocBytes += alignUp(b, gpu.blas_alignment);
        m.pooledBytes += alignUp(b, gpu.pool_alignment);
        m.compactedPooledBytes += alignUp(static_cast<std::uint64_t>(std::ceil(double(b) * gpu.blas_compaction)),
                                          gpu.pool_alignment);
    }
    return m;
}

nlohmann::json toJson(const BlasMemory& m) {
    return {{"clusters", m.clusters},
            {"triangles", m.triangles},
            {"gpu_bytes", m.gpuBytes},
            {"per_blas_allocation_bytes", m.perBlasAllocBytes},
            {"per_blas_allocation_waste", m.perBlasWaste()},
            {"pooled_bytes", m.pooledBytes},
            {"pooled_waste", m.pooledWaste()},
            {"compacted_pooled_bytes", m.compactedPooledBytes},
            {"embree_bytes", m.embreeBytes},
            {"embree_bytes_per_cluster", m.clusters ? double(m.embreeBytes) / double(m.clusters) : 0.0}};
}

}  // namespace accretion
