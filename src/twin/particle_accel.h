#pragma once
// The GPU pipeline's acceleration structure on OptiX (docs/MODEL.md section 2),
// in every layout of geometry.layout:
//  - clusters: one BLAS per particle cluster of two triangles per billboard
//    (or one built-in sphere per particle for geometry.primitive = sphere);
//    cluster_size >= the particle count gives one BLAS for all particles;
//  - instances: one BLAS of one unit billboard, built once, and one TLAS
//    instance per particle whose transform places, scales and orients it;
//  - aabbs: one BLAS per cluster of procedural boxes, one per particle,
//    intersected by the billboard intersection program.
// The cluster BLASes are built every frame by their policy (rebuild with
// fast build, refit, fast_trace, partial: a round-robin window of the
// clusters), in one 256-B-aligned pool or one allocation per BLAS, optionally
// compacted, and issued from one host thread over one or more streams or
// from several host threads. (Capturing the builds as one CUDA graph was
// tried: OptiX 9.0 on driver 580 fails optixAccelBuild under stream capture,
// bench/gpu/README.md.) With gpu.omm, every
// triangle carries one of two opacity micromaps of the disc (the quad's two
// uv triangles; the CPU's classification, in OptiX's micro-triangle order).
#include <cstdint>
#include <vector>

#include "accretion/geometry/billboard.h"
#include "accretion/geometry/clustering.h"
#include "accretion/scene/settings.h"
#include "device_buffer.h"
#include "gpu_timer.h"

namespace accretion::twin {

struct AccelOptions {
    AccelLayout layout = AccelLayout::clusters;
    bool spheres = false;  ///< built-in spheres instead of billboards (clusters layout only)
    BuildPolicy build = BuildPolicy::rebuild;
    double rebuildFraction = 0.7;
    bool pooled = true;    ///< one pool (256-B-aligned offsets) rather than one cudaMalloc per BLAS
    bool compact = false;  ///< compact each BLAS after its build (rebuild, fast_trace)
    unsigned streams = 1;  ///< BLAS builds spread round robin over this many streams (each its own scratch)
    unsigned hostThreads = 1;  ///< host threads issuing the BLAS builds (each its own stream and scratch)
    OmmMode omm = OmmMode::off;  ///< opacity micromaps of the disc alpha (gpu.omm; disc-alpha billboards only)
    std::uint32_t ommLevel = 4;  ///< their subdivision level (gpu.omm_level)
};

/// The OptiX build flags of the BLASes (the built-in sphere module takes them too).
unsigned blasBuildFlags(const AccelOptions& options);

/// What one frame's build did and holds.
struct AccelStats {
    std::size_t blases = 0;           ///< BLAS count (instances: 1)
    std::size_t instances = 0;        ///< TLAS instances
    std::size_t primitives = 0;       ///< triangles, spheres or boxes in all BLASes
    std::size_t largestBlas = 0;      ///< primitives of the largest BLAS
    std::size_t rebuiltBlases = 0;    ///< BLAS built or refitted this frame
    bool refitted = false, partial = false;
    std::size_t blasBytes = 0;        ///< sum of the BLAS outputs (after compaction, if any)
    std::size_t poolBytes = 0;        ///< the BLAS memory held: the pool, or what the per-BLAS allocations took of the device (cudaMemGetInfo)
    std::size_t tempBytes = 0;        ///< the scratch buffers (one per build lane)
    std::size_t tlasBytes = 0;        ///< the TLAS output
    std::size_t inputBytes = 0;       ///< build inputs: vertices, spheres, boxes or instance records
    std::size_t ommBytes = 0;         ///< the opacity micromap array (two micromaps every BLAS shares)
    double blasEnqueueMs = 0.0;       ///< host time of issuing the BLAS builds (the optixAccelBuild calls)
    std::size_t totalBytes() const { return poolBytes + tempBytes + tlasBytes + inputBytes + ommBytes; }
};

/// Device arrays of the frame's particles the build reads.
struct DeviceParticles {
    std::uint32_t count = 0;
    const Vec3* position = nullptr;
    const float* radius = nullptr;
    const BillboardFrame* frames = nullptr;
};

class ParticleAccel {
public:
    ParticleAccel(OptixDeviceContext context, AccelOptions options);
    ~ParticleAccel();
    ParticleAccel(const ParticleAccel&) = delete;
    ParticleAccel& operator=(const ParticleAccel&) = delete;

    /// Build the frame. clusters: this frame's (rebuild, fast_trace, and the
    /// first build), or null to keep the last ones (refit, partial); unused
    /// by the instances layout. Passes timed: expandPrimitives or
    /// writeInstances, buildBlas, compactBlas, buildTlas.
    void build(const Clusters* clusters, const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer);

    OptixTraversableHandle tlas() const { return tlas_; }
    const std::uint32_t* clusterParticle() const { return clusterParticle_.as<std::uint32_t>(); }
    const std::uint32_t* clusterOffset() const { return clusterOffset_.as<std::uint32_t>(); }
    const AccelStats& stats() const { return stats_; }
    bool built() const { return tlas_ != 0; }

private:
    bool instanced() const { return options_.layout == AccelLayout::instances; }
    void setClusters(const Clusters& clusters);
    void buildInstances(const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer);
    void expandPrimitives(std::size_t first, std::size_t count, const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer);
    void compactBlases(cudaStream_t stream, GpuTimer& timer);
    void setPrimitiveBuffers(std::size_t C, std::size_t n, std::uint32_t largest);
    void sizeBlasMemory(std::size_t C);
    /// Cluster c's build input; `usage` (which it points at) receives its micromap usage.
    OptixBuildInput blasInput(std::size_t c, OptixOpacityMicromapUsageCount& usage) const;
    unsigned buildFlags() const { return blasBuildFlags(options_); }
    /// The BLAS builds of clusters (first + k) mod C, k < count, by lanes and threads.
    void issueBlasBuilds(std::size_t first, std::size_t count, bool refit, bool compact, cudaStream_t stream);
    void issueLane(unsigned lane, unsigned lanes, std::size_t first, std::size_t count, const OptixAccelBuildOptions& opts,
                   bool compact, cudaStream_t stream);
    void buildUnitBillboard(cudaStream_t stream);
    void buildTlas(const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer);
    void buildMicromaps(cudaStream_t stream);

    OptixDeviceContext context_;
    AccelOptions options_;
    unsigned lanes_ = 1;                      ///< build streams (the frame's first): max(streams, hostThreads)
    std::vector<std::uint32_t> offset_;       ///< host copy of the cluster offsets
    std::vector<std::uint32_t> particle_;     ///< host copy of the cluster members (a repeated frame's are not set up again)
    DeviceBuffer clusterParticle_, clusterOffset_, primitives_, radii_, indices_;
    DeviceBuffer ommArray_, ommIndices_;      ///< the micromap array; per triangle 0 or 1 (its uv triangle)
    OptixOpacityMicromapFormat ommFormat_ = OPTIX_OPACITY_MICROMAP_FORMAT_NONE;
    std::vector<CUdeviceptr> primitivePointers_, radiusPointers_;  ///< per cluster (build inputs point at them)
    std::vector<std::size_t> outputBytes_, blasOffset_;
    DeviceBuffer pool_, compactPool_, compactSizes_;
    std::vector<DeviceBuffer> temp_;           ///< one scratch buffer per build lane
    std::vector<cudaStream_t> buildStreams_;   ///< lanes beside the frame's stream (lanes_ - 1)
    cudaEvent_t fork_ = nullptr;
    std::vector<cudaEvent_t> join_;
    std::vector<DeviceBuffer> perBlas_;
    std::vector<OptixTraversableHandle> handles_;
    // instances: the unit billboard's BLAS, built once.
    DeviceBuffer unitVertices_, unitBlas_;
    OptixTraversableHandle unitHandle_ = 0;
    DeviceBuffer instances_, tlasBuffer_, tlasTemp_;
    OptixTraversableHandle tlas_ = 0;
    std::size_t partialCursor_ = 0;
    AccelStats stats_;
};

}  // namespace accretion::twin
