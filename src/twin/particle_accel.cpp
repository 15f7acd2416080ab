#include "particle_accel.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <map>
#include <thread>

#include <optix_micromap.h>
#include <optix_stubs.h>

#include "accretion/core/error.h"
#include "accretion/geometry/opacity_micromap.h"
#include "kernels.h"

namespace accretion::twin {
namespace {

constexpr std::size_t kPoolAlignment = 256;  // >= OPTIX_ACCEL_BUFFER_BYTE_ALIGNMENT
std::size_t alignUp(std::size_t x, std::size_t a) { return (x + a - 1) / a * a; }

const unsigned kGeometryFlags = OPTIX_GEOMETRY_FLAG_NONE;  // any-hit allowed: identity exclusion, alpha

/// Primitives per particle in a cluster BLAS: two triangles per billboard, one sphere or box.
std::size_t primitivesPerParticle(const AccelOptions& o) {
    return o.layout == AccelLayout::clusters && !o.spheres ? 2 : 1;
}

}  // namespace

ParticleAccel::ParticleAccel(OptixDeviceContext context, AccelOptions options) : context_(context), options_(options) {
    if (options_.spheres && options_.layout != AccelLayout::clusters)
        throw InputError("accretion-optix: geometry.primitive = \"sphere\" runs with geometry.layout = \"clusters\" only");
    lanes_ = std::max({1u, options_.streams, options_.hostThreads});
    temp_.resize(lanes_);
    buildStreams_.resize(lanes_ - 1);
    join_.resize(lanes_ - 1);
    for (cudaStream_t& s : buildStreams_) CUDA_CHECK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking));
    for (cudaEvent_t& e : join_) CUDA_CHECK(cudaEventCreateWithFlags(&e, cudaEventDisableTiming));
    CUDA_CHECK(cudaEventCreateWithFlags(&fork_, cudaEventDisableTiming));
}

ParticleAccel::~ParticleAccel() {
    for (cudaStream_t s : buildStreams_) cudaStreamDestroy(s);
    for (cudaEvent_t e : join_) cudaEventDestroy(e);
    if (fork_) cudaEventDestroy(fork_);
}

unsigned blasBuildFlags(const AccelOptions& o) {
    unsigned f = o.build == BuildPolicy::fast_trace ? OPTIX_BUILD_FLAG_PREFER_FAST_TRACE : OPTIX_BUILD_FLAG_PREFER_FAST_BUILD;
    if (o.build == BuildPolicy::refit) f |= OPTIX_BUILD_FLAG_ALLOW_UPDATE;
    if (o.compact) f |= OPTIX_BUILD_FLAG_ALLOW_COMPACTION;
    return f;
}

OptixBuildInput ParticleAccel::blasInput(std::size_t c, OptixOpacityMicromapUsageCount& usage) const {
    const std::uint32_t n = offset_[c + 1] - offset_[c];
    OptixBuildInput in{};
    if (options_.layout == AccelLayout::aabbs) {
        in.type = OPTIX_BUILD_INPUT_TYPE_CUSTOM_PRIMITIVES;
        auto& a = in.customPrimitiveArray;
        a.aabbBuffers = &primitivePointers_[c];
        a.numPrimitives = n;
        a.strideInBytes = sizeof(OptixAabb);
        a.flags = &kGeometryFlags;
        a.numSbtRecords = 1;
        return in;
    }
    if (options_.spheres) {
        in.type = OPTIX_BUILD_INPUT_TYPE_SPHERES;
        auto& s = in.sphereArray;
        s.vertexBuffers = &primitivePointers_[c];
        s.vertexStrideInBytes = sizeof(Vec3);
        s.numVertices = n;
        s.radiusBuffers = &radiusPointers_[c];
        s.radiusStrideInBytes = sizeof(float);
        s.singleRadius = 0;
        s.flags = &kGeometryFlags;
        s.numSbtRecords = 1;
        return in;
    }
    in.type = OPTIX_BUILD_INPUT_TYPE_TRIANGLES;
    auto& t = in.triangleArray;
    t.vertexFormat = OPTIX_VERTEX_FORMAT_FLOAT3;
    t.vertexStrideInBytes = sizeof(Vec3);
    t.numVertices = 4 * n;
    t.vertexBuffers = &primitivePointers_[c];
    t.indexFormat = OPTIX_INDICES_FORMAT_UNSIGNED_INT3;
    t.indexStrideInBytes = 3 * sizeof(std::uint32_t);
    t.numIndexTriplets = 2 * n;
    t.indexBuffer = indices_.address();  // the same local indices in every cluster
    t.flags = &kGeometryFlags;
    t.numSbtRecords = 1;
    if (options_.omm != OmmMode::off) {
        OptixBuildInputOpacityMicromap& m = t.opacityMicromap;
        m.indexingMode = OPTIX_OPACITY_MICROMAP_ARRAY_INDEXING_MODE_INDEXED;
        m.opacityMicromapArray = ommArray_.address();
        m.indexBuffer = ommIndices_.address();  // 0, 1, 0, 1, ...: the same in every cluster
        m.indexSizeInBytes = 2;
        m.numMicromapUsageCounts = 1;
        usage = {2 * n, options_.ommLevel, ommFormat_};  // every triangle uses one of the two micromaps
        m.micromapUsageCounts = &usage;
    }
    return in;
}

void ParticleAccel::setClusters(const Clusters& clusters) {
    // The same clusters as the last build (a repeated frame): nothing to set up.
    if (clusters.offset == offset_ && clusters.particle == particle_) return;
    offset_ = clusters.offset;
    particle_ = clusters.particle;
    clusterParticle_.upload(clusters.particle);
    clusterOffset_.upload(clusters.offset);
    const std::size_t C = clusters.count(), n = clusters.particle.size();
    std::uint32_t largest = 0;
    for (std::size_t c = 0; c < C; ++c) largest = std::max(largest, offset_[c + 1] - offset_[c]);
    setPrimitiveBuffers(C, n, largest);
    sizeBlasMemory(C);
    handles_.assign(C, 0);
    partialCursor_ = 0;
    stats_.blases = C;
    stats_.instances = C;
    stats_.primitives = primitivesPerParticle(options_) * n;
    stats_.largestBlas = primitivesPerParticle(options_) * largest;
}

/// The build inputs' device buffers for every cluster: boxes, spheres and
/// their radii, or quads' four corners with the shared index buffer (and
/// the micromap indices).
void ParticleAccel::setPrimitiveBuffers(std::size_t C, std::size_t n, std::uint32_t largest) {
    primitivePointers_.resize(C);
    radiusPointers_.assign(C, 0);
    if (options_.layout == AccelLayout::aabbs) {
        primitives_.reserve(n * sizeof(OptixAabb));
        for (std::size_t c = 0; c < C; ++c) primitivePointers_[c] = primitives_.address() + offset_[c] * sizeof(OptixAabb);
        stats_.inputBytes = n * sizeof(OptixAabb);
    } else if (options_.spheres) {
        primitives_.reserve(n * sizeof(Vec3));
        radii_.reserve(n * sizeof(float));
        for (std::size_t c = 0; c < C; ++c) {
            primitivePointers_[c] = primitives_.address() + offset_[c] * sizeof(Vec3);
            radiusPointers_[c] = radii_.address() + offset_[c] * sizeof(float);
        }
        stats_.inputBytes = n * (sizeof(Vec3) + sizeof(float));
    } else {
        primitives_.reserve(4 * n * sizeof(Vec3));
        std::vector<std::uint32_t> idx(6 * std::size_t(largest));
        for (std::uint32_t k = 0; k < largest; ++k) {
            const std::uint32_t v = 4 * k, q[6] = {v, v + 1, v + 2, v, v + 2, v + 3};
            std::copy(q, q + 6, idx.begin() + 6 * k);
        }
        indices_.upload(idx);
        if (options_.omm != OmmMode::off) {
            std::vector<std::int16_t> tri(2 * std::size_t(largest));
            for (std::size_t k = 0; k < tri.size(); ++k) tri[k] = std::int16_t(k & 1);
            ommIndices_.upload(tri);
            if (!ommArray_.bytes()) buildMicromaps(nullptr);
        }
        for (std::size_t c = 0; c < C; ++c) primitivePointers_[c] = primitives_.address() + 4 * std::size_t(offset_[c]) * sizeof(Vec3);
        stats_.inputBytes = 4 * n * sizeof(Vec3) + idx.size() * sizeof(std::uint32_t);
    }
}

/// Every BLAS's output bytes (computed once per cluster size: clusters of
/// one size need the same memory), their places in the pool or their own
/// allocations, and the scratch of the builds.
void ParticleAccel::sizeBlasMemory(std::size_t C) {
    // Sizes per cluster size (clusters of one size need the same memory).
    const OptixAccelBuildOptions opts{buildFlags(), OPTIX_BUILD_OPERATION_BUILD, {}};
    std::map<std::uint32_t, OptixAccelBufferSizes> bySize;
    outputBytes_.resize(C);
    blasOffset_.resize(C);
    std::size_t tempBytes = 0, pool = 0;
    for (std::size_t c = 0; c < C; ++c) {
        const std::uint32_t m = offset_[c + 1] - offset_[c];
        auto it = bySize.find(m);
        if (it == bySize.end()) {
            OptixOpacityMicromapUsageCount usage;
            const OptixBuildInput in = blasInput(c, usage);
            OptixAccelBufferSizes s{};
            OPTIX_CHECK(optixAccelComputeMemoryUsage(context_, &opts, &in, 1, &s));
            it = bySize.emplace(m, s).first;
        }
        outputBytes_[c] = it->second.outputSizeInBytes;
        tempBytes = std::max({tempBytes, it->second.tempSizeInBytes, it->second.tempUpdateSizeInBytes});
        blasOffset_[c] = pool;
        pool = alignUp(pool + outputBytes_[c], kPoolAlignment);
    }
    stats_.tempBytes = 0;
    for (DeviceBuffer& t : temp_) {
        t.reserve(tempBytes);
        stats_.tempBytes += t.bytes();
    }
    perBlas_.clear();
    if (options_.pooled) {
        pool_.reserve(pool);
        stats_.poolBytes = pool_.bytes();
    } else {
        // What one cudaMalloc per BLAS really takes: the device's free memory before and after.
        std::size_t free0 = 0, free1 = 0, total = 0;
        CUDA_CHECK(cudaMemGetInfo(&free0, &total));
        perBlas_.resize(C);
        for (std::size_t c = 0; c < C; ++c) perBlas_[c].resize(outputBytes_[c]);
        CUDA_CHECK(cudaMemGetInfo(&free1, &total));
        stats_.poolBytes = free0 > free1 ? free0 - free1 : 0;
    }
}

void ParticleAccel::issueLane(unsigned lane, unsigned lanes, std::size_t first, std::size_t count,
                              const OptixAccelBuildOptions& opts, bool compact, cudaStream_t stream) {
    const std::size_t C = handles_.size();
    const cudaStream_t bs = lane == 0 ? stream : buildStreams_[lane - 1];
    for (std::size_t k = lane; k < count; k += lanes) {
        const std::size_t c = (first + k) % C;
        OptixOpacityMicromapUsageCount usage;
        const OptixBuildInput in = blasInput(c, usage);
        const CUdeviceptr out = options_.pooled ? pool_.address() + blasOffset_[c] : perBlas_[c].address();
        OptixAccelEmitDesc emit{compactSizes_.address() + c * sizeof(std::uint64_t), OPTIX_PROPERTY_TYPE_COMPACTED_SIZE};
        OPTIX_CHECK(optixAccelBuild(context_, bs, &opts, &in, 1, temp_[lane].address(), temp_[lane].bytes(), out,
                                    outputBytes_[c], &handles_[c], compact ? &emit : nullptr, compact ? 1 : 0));
    }
}

void ParticleAccel::issueBlasBuilds(std::size_t first, std::size_t count, bool refit, bool compact, cudaStream_t stream) {
    const OptixAccelBuildOptions opts{buildFlags(), refit ? OPTIX_BUILD_OPERATION_UPDATE : OPTIX_BUILD_OPERATION_BUILD, {}};
    const unsigned L = lanes_;
    // Lanes (streams) forked from and joined to the frame's stream; the
    // builds of one lane run one after another, lanes may overlap.
    {
        const cudaStream_t s = stream;
        if (L > 1) {
            CUDA_CHECK(cudaEventRecord(fork_, s));
            for (cudaStream_t bs : buildStreams_) CUDA_CHECK(cudaStreamWaitEvent(bs, fork_, 0));
        }
        const unsigned T = std::max(1u, options_.hostThreads);
        if (T == 1) {
            for (unsigned l = 0; l < L; ++l) issueLane(l, L, first, count, opts, compact, s);
        } else {
            // Host thread t issues lanes t, t + T, ...: optixAccelBuild is
            // thread safe, and each lane has its own stream and scratch.
            std::vector<std::thread> threads;
            for (unsigned t = 0; t < T; ++t)
                threads.emplace_back([&, t] {
                    for (unsigned l = t; l < L; l += T) issueLane(l, L, first, count, opts, compact, s);
                });
            for (std::thread& th : threads) th.join();
        }
        for (unsigned l = 1; l < L; ++l) {
            CUDA_CHECK(cudaEventRecord(join_[l - 1], buildStreams_[l - 1]));
            CUDA_CHECK(cudaStreamWaitEvent(s, join_[l - 1], 0));
        }
    }
}

void ParticleAccel::buildUnitBillboard(cudaStream_t stream) {
    // Corners -+1, -+1 in the plane z = 0, in expandBillboards' order, so
    // that a hit's barycentrics give the quad uv as in the cluster layout.
    const std::vector<Vec3> v = {Vec3(-1, -1, 0), Vec3(1, -1, 0), Vec3(1, 1, 0), Vec3(-1, 1, 0)};
    unitVertices_.upload(v);
    indices_.upload(std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3});
    offset_ = {0, 1};
    primitivePointers_ = {unitVertices_.address()};
    if (options_.omm != OmmMode::off) {
        ommIndices_.upload(std::vector<std::int16_t>{0, 1});
        buildMicromaps(nullptr);
    }
    OptixOpacityMicromapUsageCount usage;
    const OptixBuildInput in = blasInput(0, usage);
    const OptixAccelBuildOptions opts{OPTIX_BUILD_FLAG_PREFER_FAST_TRACE, OPTIX_BUILD_OPERATION_BUILD, {}};
    OptixAccelBufferSizes s{};
    OPTIX_CHECK(optixAccelComputeMemoryUsage(context_, &opts, &in, 1, &s));
    DeviceBuffer temp(s.tempSizeInBytes);
    unitBlas_.resize(s.outputSizeInBytes);
    OPTIX_CHECK(optixAccelBuild(context_, stream, &opts, &in, 1, temp.address(), temp.bytes(), unitBlas_.address(),
                                unitBlas_.bytes(), &unitHandle_, nullptr, 0));
    CUDA_CHECK(cudaStreamSynchronize(stream));
    stats_.blasBytes = stats_.poolBytes = s.outputSizeInBytes;
    stats_.blases = 1;
    stats_.largestBlas = 2;
}

/// The instances layout: the unit billboard once; every frame the instances
/// and the TLAS (refit: the TLAS updated after its first build).
void ParticleAccel::buildInstances(const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer) {
    const BuildPolicy policy = options_.build;
    if (!unitHandle_) buildUnitBillboard(stream);
    {
        GpuScope s(timer, Pass::buildClusters, "writeInstances");
        instances_.reserve(std::size_t(particles.count) * sizeof(OptixInstance));
        writeInstances(particles.count, particles.position, particles.radius, particles.frames, unitHandle_,
                       instances_.as<OptixInstance>(), stream);
        CUDA_CHECK(cudaGetLastError());
    }
    stats_.refitted = policy == BuildPolicy::refit && built();
    stats_.instances = particles.count;
    stats_.primitives = 2;
    stats_.rebuiltBlases = 0;
    stats_.inputBytes = std::size_t(particles.count) * sizeof(OptixInstance);
    {
        GpuScope s(timer, Pass::buildClusters, "buildTlas");
        buildTlas(particles, stream, timer);
    }
}

/// The primitives of clusters [first, first + count) mod C from the
/// particles: one or two ranges of their slots.
void ParticleAccel::expandPrimitives(std::size_t first, std::size_t count, const DeviceParticles& particles, cudaStream_t stream,
                                     GpuTimer& timer) {
    const std::size_t C = offset_.size() - 1;
    {
        GpuScope s(timer, Pass::buildClusters, "expandPrimitives");
        auto expand = [&](std::size_t c0, std::size_t c1) {
            const std::uint32_t b = offset_[c0], e = offset_[c1];
            if (options_.layout == AccelLayout::aabbs)
                expandBillboardBoxes(clusterParticle(), b, e, particles.position, particles.radius, particles.frames,
                                     primitives_.as<OptixAabb>(), stream);
            else if (options_.spheres)
                expandSpheres(clusterParticle(), b, e, particles.position, particles.radius, primitives_.as<Vec3>(),
                              radii_.as<float>(), stream);
            else
                expandBillboards(clusterParticle(), b, e, particles.position, particles.radius, particles.frames,
                                 primitives_.as<Vec3>(), stream);
        };
        if (first + count <= C) expand(first, first + count);
        else {
            expand(first, C);
            expand(0, first + count - C);
        }
        CUDA_CHECK(cudaGetLastError());
    }
}

/// Every BLAS compacted into one pool (the sizes their builds emitted).
void ParticleAccel::compactBlases(cudaStream_t stream, GpuTimer& timer) {
    const std::size_t C = offset_.size() - 1;
    GpuScope s(timer, Pass::buildClusters, "compactBlas");
    std::vector<std::uint64_t> sizes = compactSizes_.download<std::uint64_t>(C);  // synchronises
    std::vector<std::size_t> at(C);
    std::size_t pool = 0;
    for (std::size_t c = 0; c < C; ++c) {
        at[c] = pool;
        pool = alignUp(pool + sizes[c], kPoolAlignment);
    }
    compactPool_.reserve(pool);
    stats_.blasBytes = 0;
    for (std::size_t c = 0; c < C; ++c) {
        OPTIX_CHECK(optixAccelCompact(context_, stream, handles_[c], compactPool_.address() + at[c], sizes[c], &handles_[c]));
        stats_.blasBytes += sizes[c];
    }
    stats_.poolBytes = compactPool_.bytes();
}

void ParticleAccel::build(const Clusters* clusters, const DeviceParticles& particles, cudaStream_t stream, GpuTimer& timer) {
    const BuildPolicy policy = options_.build;
    if (instanced()) return buildInstances(particles, stream, timer);
    const bool keep = !clusters;
    ACC_CHECK(clusters || (built() && (policy == BuildPolicy::refit || policy == BuildPolicy::partial)));
    if (!keep) setClusters(*clusters);
    const std::size_t C = offset_.size() - 1;
    const bool refit = keep && policy == BuildPolicy::refit;
    std::size_t first = 0, count = C;
    if (keep && policy == BuildPolicy::partial) {
        count = std::min(C, static_cast<std::size_t>(std::ceil(options_.rebuildFraction * double(C))));
        first = partialCursor_ % std::max<std::size_t>(C, 1);
        partialCursor_ += count;
    }
    expandPrimitives(first, count, particles, stream, timer);
    const bool compact = options_.compact && !refit && policy != BuildPolicy::partial;
    if (compact) compactSizes_.reserve(C * sizeof(std::uint64_t));
    {
        GpuScope s(timer, Pass::buildClusters, "buildBlas");
        const auto host0 = std::chrono::steady_clock::now();
        issueBlasBuilds(first, count, refit, compact, stream);
        stats_.blasEnqueueMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - host0).count();
    }
    stats_.blasBytes = 0;
    for (std::size_t c = 0; c < C; ++c) stats_.blasBytes += outputBytes_[c];
    if (compact) compactBlases(stream, timer);
    {
        GpuScope s(timer, Pass::buildClusters, "buildTlas");
        buildTlas(particles, stream, timer);
    }
    stats_.rebuiltBlases = count;
    stats_.refitted = refit;
    stats_.partial = keep && policy == BuildPolicy::partial;
}

void ParticleAccel::buildMicromaps(cudaStream_t stream) {
    // The CPU's classification (docs/MODEL.md section 6) of both uv triangles,
    // looked up at the centroid of each OptiX micro-triangle (OptiX numbers
    // them along a space-filling curve, the CPU row by row). 4-state keeps
    // unknown, as unknown-opaque where the 2-state map says opaque.
    const std::uint32_t L = options_.ommLevel;
    const bool four = options_.omm == OmmMode::four_state;
    const OpacityMicromap fourMap(L, true), twoMap(L, false);
    const std::uint32_t micro = 1u << (2 * L), bits = four ? 2 : 1;
    const std::size_t stride = alignUp((std::size_t(micro) * bits + 7) / 8, 16);
    std::vector<std::uint8_t> data(2 * stride, 0);
    for (std::uint32_t tri = 0; tri < 2; ++tri)
        for (std::uint32_t k = 0; k < micro; ++k) {
            float2 b0, b1, b2;
            optixMicromapIndexToBaseBarycentrics(k, L, b0, b1, b2);
            const float u = (b0.x + b1.x + b2.x) / 3.0f, v = (b0.y + b1.y + b2.y) / 3.0f;
            const OmmState s = fourMap.lookup(tri, u, v), s2 = twoMap.lookup(tri, u, v);
            std::uint32_t state = s2 == OmmState::opaque ? OPTIX_OPACITY_MICROMAP_STATE_OPAQUE : OPTIX_OPACITY_MICROMAP_STATE_TRANSPARENT;
            if (four && s == OmmState::unknown)
                state = s2 == OmmState::opaque ? OPTIX_OPACITY_MICROMAP_STATE_UNKNOWN_OPAQUE : OPTIX_OPACITY_MICROMAP_STATE_UNKNOWN_TRANSPARENT;
            const std::size_t bit = std::size_t(k) * bits;
            data[tri * stride + bit / 8] |= std::uint8_t(state << (bit % 8));
        }
    const OptixOpacityMicromapFormat format = four ? OPTIX_OPACITY_MICROMAP_FORMAT_4_STATE : OPTIX_OPACITY_MICROMAP_FORMAT_2_STATE;
    std::vector<OptixOpacityMicromapDesc> desc(2);
    for (std::uint32_t tri = 0; tri < 2; ++tri)
        desc[tri] = {static_cast<unsigned>(tri * stride), static_cast<unsigned short>(L), static_cast<unsigned short>(format)};
    DeviceBuffer input, descs, temp;
    input.upload(data);
    descs.upload(desc);
    const OptixOpacityMicromapHistogramEntry histogram{2, L, format};
    OptixOpacityMicromapArrayBuildInput in{};
    in.flags = OPTIX_OPACITY_MICROMAP_FLAG_PREFER_FAST_TRACE;
    in.inputBuffer = input.address();
    in.perMicromapDescBuffer = descs.address();
    in.numMicromapHistogramEntries = 1;
    in.micromapHistogramEntries = &histogram;
    OptixMicromapBufferSizes sizes{};
    OPTIX_CHECK(optixOpacityMicromapArrayComputeMemoryUsage(context_, &in, &sizes));
    ommArray_.reserve(sizes.outputSizeInBytes);
    temp.reserve(sizes.tempSizeInBytes);
    const OptixMicromapBuffers buffers{ommArray_.address(), sizes.outputSizeInBytes, temp.address(), sizes.tempSizeInBytes};
    OPTIX_CHECK(optixOpacityMicromapArrayBuild(context_, stream, &in, &buffers));
    CUDA_CHECK(cudaStreamSynchronize(stream));
    stats_.ommBytes = sizes.outputSizeInBytes;
    ommFormat_ = format;
}

void ParticleAccel::buildTlas(const DeviceParticles& particles, cudaStream_t stream, GpuTimer&) {
    std::size_t count = 0;
    if (instanced()) {
        count = particles.count;  // written on the device by writeInstances
    } else {
        count = handles_.size();
        std::vector<OptixInstance> inst(count);
        const float identity[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
        for (std::size_t c = 0; c < count; ++c) {
            OptixInstance& i = inst[c];
            std::memcpy(i.transform, identity, sizeof identity);
            i.instanceId = static_cast<unsigned>(c);
            i.sbtOffset = 0;
            i.visibilityMask = 255;
            i.flags = OPTIX_INSTANCE_FLAG_NONE;
            i.traversableHandle = handles_[c];
        }
        instances_.reserve(count * sizeof(OptixInstance));
        CUDA_CHECK(cudaMemcpyAsync(instances_.as<void>(), inst.data(), count * sizeof(OptixInstance), cudaMemcpyHostToDevice, stream));
    }
    OptixBuildInput in{};
    in.type = OPTIX_BUILD_INPUT_TYPE_INSTANCES;
    in.instanceArray.instances = instances_.address();
    in.instanceArray.numInstances = static_cast<unsigned>(count);
    // The instances layout's refit policy updates the TLAS (its instances
    // moved); every other layout rebuilds its (small) TLAS.
    const bool updatable = instanced() && options_.build == BuildPolicy::refit;
    const bool update = updatable && tlas_ != 0;
    const OptixAccelBuildOptions opts{OPTIX_BUILD_FLAG_PREFER_FAST_BUILD | (updatable ? unsigned(OPTIX_BUILD_FLAG_ALLOW_UPDATE) : 0u),
                                      update ? OPTIX_BUILD_OPERATION_UPDATE : OPTIX_BUILD_OPERATION_BUILD, {}};
    OptixAccelBufferSizes s{};
    OPTIX_CHECK(optixAccelComputeMemoryUsage(context_, &opts, &in, 1, &s));
    tlasBuffer_.reserve(s.outputSizeInBytes);
    tlasTemp_.reserve(std::max(s.tempSizeInBytes, s.tempUpdateSizeInBytes));
    OPTIX_CHECK(optixAccelBuild(context_, stream, &opts, &in, 1, tlasTemp_.address(), tlasTemp_.bytes(), tlasBuffer_.address(),
                                tlasBuffer_.bytes(), &tlas_, nullptr, 0));
    stats_.tlasBytes = s.outputSizeInBytes;
    if (instanced()) stats_.tempBytes = tlasTemp_.bytes();
}

}  // namespace accretion::twin
