#include "kernels.h"

namespace accretion::twin {
namespace {

constexpr unsigned kThreads = 256;
unsigned blocksFor(std::uint32_t n) { return (n + kThreads - 1) / kThreads; }

/// The thread's slot of the cluster order in [begin, end), false past its end.
__device__ inline bool slotOf(std::uint32_t begin, std::uint32_t end, std::uint32_t& slot) {
    slot = begin + blockIdx.x * blockDim.x + threadIdx.x;
    return slot < end;
}

__global__ void expandBillboardsKernel(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                                       const Vec3* position, const float* radius, const BillboardFrame* frames,
                                       Vec3* vertices) {
    std::uint32_t slot;
    if (!slotOf(begin, end, slot)) return;
    const std::uint32_t i = clusterParticle[slot];
    const Vec3 p = position[i];
    const Vec3 a = radius[i] * frames[i].right, b = radius[i] * frames[i].up;
    Vec3* v = vertices + 4 * std::size_t(slot);
    v[0] = p - a - b;
    v[1] = p + a - b;
    v[2] = p + a + b;
    v[3] = p - a + b;
}

__global__ void expandSpheresKernel(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                                    const Vec3* position, const float* radius, Vec3* centres, float* radii) {
    std::uint32_t slot;
    if (!slotOf(begin, end, slot)) return;
    const std::uint32_t i = clusterParticle[slot];
    centres[slot] = position[i];
    radii[slot] = radius[i];
}

__global__ void expandBillboardBoxesKernel(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                                           const Vec3* position, const float* radius, const BillboardFrame* frames,
                                           OptixAabb* boxes) {
    std::uint32_t slot;
    if (!slotOf(begin, end, slot)) return;
    const std::uint32_t i = clusterParticle[slot];
    const Vec3 e = billboardExtent(radius[i], frames[i]);
    const Vec3 lo = position[i] - e, hi = position[i] + e;
    boxes[slot] = {nextafterf(lo.x, -INFINITY), nextafterf(lo.y, -INFINITY), nextafterf(lo.z, -INFINITY),
                   nextafterf(hi.x, INFINITY),  nextafterf(hi.y, INFINITY),  nextafterf(hi.z, INFINITY)};
}

__global__ void writeInstancesKernel(std::uint32_t count, const Vec3* position, const float* radius,
                                     const BillboardFrame* frames, OptixTraversableHandle unit, OptixInstance* instances) {
    const std::uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= count) return;
    const Vec3 p = position[i];
    const float r = radius[i];
    const BillboardFrame f = frames[i];
    const Vec3 a = r * f.right, b = r * f.up, n = f.normal();
    OptixInstance& o = instances[i];
    const float m[12] = {a.x, b.x, n.x, p.x, a.y, b.y, n.y, p.y, a.z, b.z, n.z, p.z};
    for (int k = 0; k < 12; ++k) o.transform[k] = m[k];
    o.instanceId = i;
    o.sbtOffset = 0;
    o.visibilityMask = 255;
    o.flags = OPTIX_INSTANCE_FLAG_NONE;
    o.traversableHandle = unit;
}

}  // namespace

void expandBillboards(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                      const float* radius, const BillboardFrame* frames, Vec3* vertices, cudaStream_t stream) {
    if (end <= begin) return;
    expandBillboardsKernel<<<blocksFor(end - begin), kThreads, 0, stream>>>(clusterParticle, begin, end, position, radius,
                                                                             frames, vertices);
}

void expandSpheres(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                   const float* radius, Vec3* centres, float* radii, cudaStream_t stream) {
    if (end <= begin) return;
    expandSpheresKernel<<<blocksFor(end - begin), kThreads, 0, stream>>>(clusterParticle, begin, end, position, radius,
                                                                          centres, radii);
}

void expandBillboardBoxes(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                          const Vec3* position, const float* radius, const BillboardFrame* frames, OptixAabb* boxes,
                          cudaStream_t stream) {
    if (end <= begin) return;
    expandBillboardBoxesKernel<<<blocksFor(end - begin), kThreads, 0, stream>>>(clusterParticle, begin, end, position,
                                                                                 radius, frames, boxes);
}

void writeInstances(std::uint32_t count, const Vec3* position, const float* radius, const BillboardFrame* frames,
                    OptixTraversableHandle unitBillboard, OptixInstance* instances, cudaStream_t stream) {
    if (!count) return;
    writeInstancesKernel<<<blocksFor(count), kThreads, 0, stream>>>(count, position, radius, frames, unitBillboard, instances);
}

}  // namespace accretion::twin
