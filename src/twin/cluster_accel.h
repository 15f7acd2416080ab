#pragma once
// The GPU pipeline's acceleration structure on OptiX (docs/MODEL.md section 2,
// seed 004): one triangle BLAS per particle cluster (two triangles per
// billboard), built every frame by its policy (rebuild with fast build,
// refit, fast_trace, partial: a round-robin window of the clusters), in one
// 256-B-aligned pool or one allocation per BLAS, optionally compacted; a TLAS
// of one instance per cluster (instance id = cluster). With gpu.omm, every
// triangle carries one of two opacity micromaps of the disc (the quad's two
// uv triangles; the CPU's OpacityMicromap classification, reordered to
// OptiX's micro-triangle order).
#include <cstdint>
#include <vector>

#include "accretion/geometry/billboard.h"
#include "accretion/geometry/clustering.h"
#include "accretion/scene/settings.h"
#include "device_buffer.h"
#include "gpu_timer.h"

namespace accretion::twin {

struct AccelOptions {
    BuildPolicy build = BuildPolicy::rebuild;
    double rebuildFraction = 0.7;
    bool pooled = true;    ///< one pool (256-B-aligned offsets) rather than one cudaMalloc per BLAS
    bool compact = false;  ///< compact each BLAS after its build (rebuild, fast_trace)
    unsigned streams = 1;  ///< BLAS builds spread round robin over this many streams (each its own scratch)
    OmmMode omm = OmmMode::off;  ///< opacity micromaps of the disc alpha (gpu.omm; disc-alpha billboards only)
    std::uint32_t ommLevel = 4;  ///< their subdivision level (gpu.omm_level)
};

/// What one frame's build did and holds.
struct AccelStats {
    std::size_t clusters = 0, triangles = 0;
    std::size_t rebuiltClusters = 0;  ///< BLAS built or refitted this frame
    bool refitted = false, partial = false;
    std::size_t blasBytes = 0;        ///< sum of the BLAS outputs (after compaction, if any)
    std::size_t poolBytes = 0;        ///< the BLAS memory held: the pool, or what the per-BLAS allocations took of the device (cudaMemGetInfo)
    std::size_t tempBytes = 0;        ///< the shared scratch buffer
    std::size_t tlasBytes = 0;
    std::size_t ommBytes = 0;         ///< the opacity micromap array (two micromaps every BLAS shares)
    double blasEnqueueMs = 0.0;       ///< host time of the optixAccelBuild calls of the BLAS (launch overhead)
};

/// Device arrays of the frame's particles the build reads.
struct DeviceParticles {
    const Vec3* position = nullptr;
    const float* radius = nullptr;
    const BillboardFrame* frames = nullptr;
};

class ClusterAccel {
public:
    ClusterAccel(OptixDeviceContext context, AccelOptions options);
    ~ClusterAccel();
    ClusterAccel(const ClusterAccel&) = delete;
    ClusterAccel& operator=(const ClusterAccel&) = delete;

    /// Build the frame. clusters: this frame's (rebuild, fast_trace, and the
    /// first build), or null to keep the last ones (refit, partial).
    /// Passes timed: expandBillboards, buildBlas, compactBlas, buildTlas.
    void build(const Clusters* clusters, const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer);

    OptixTraversableHandle tlas() const { return tlas_; }
    const std::uint32_t* clusterParticle() const { return clusterParticle_.as<std::uint32_t>(); }
    const std::uint32_t* clusterOffset() const { return clusterOffset_.as<std::uint32_t>(); }
    const AccelStats& stats() const { return stats_; }
    bool built() const { return !handles_.empty(); }

private:
    void setClusters(const Clusters& clusters);
    /// Cluster c's build input; `usage` (which it points at) receives its micromap usage.
    OptixBuildInput triangles(std::size_t c, OptixOpacityMicromapUsageCount& usage) const;
    unsigned buildFlags() const;
    void buildTlas(cudaStream_t stream);
    void buildMicromaps(cudaStream_t stream);

    OptixDeviceContext context_;
    AccelOptions options_;
    std::vector<std::uint32_t> offset_;       ///< host copy of the cluster offsets
    DeviceBuffer clusterParticle_, clusterOffset_, vertices_, indices_;
    DeviceBuffer ommArray_, ommIndices_;           ///< the micromap array; per triangle 0 or 1 (its uv triangle)
    OptixOpacityMicromapFormat ommFormat_ = OPTIX_OPACITY_MICROMAP_FORMAT_NONE;
    std::vector<CUdeviceptr> vertexPointers_;  ///< per cluster (build inputs point at them)
    std::vector<std::size_t> outputBytes_, blasOffset_;
    DeviceBuffer pool_, compactPool_, compactSizes_;
    std::vector<DeviceBuffer> temp_;           ///< one scratch buffer per build stream
    std::vector<cudaStream_t> buildStreams_;   ///< streams beside the frame's (options_.streams - 1)
    cudaEvent_t fork_ = nullptr;
    std::vector<cudaEvent_t> join_;
    std::vector<DeviceBuffer> perBlas_;
    std::vector<OptixTraversableHandle> handles_;
    DeviceBuffer instances_, tlasBuffer_, tlasTemp_;
    OptixTraversableHandle tlas_ = 0;
    std::size_t partialCursor_ = 0;
    AccelStats stats_;
};

}  // namespace accretion::twin
