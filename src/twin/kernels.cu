#include "kernels.h"

namespace accretion::twin {
namespace {

__global__ void expandBillboardsKernel(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                                       const Vec3* position, const float* radius, const BillboardFrame* frames,
                                       Vec3* vertices) {
    const std::uint32_t slot = begin + blockIdx.x * blockDim.x + threadIdx.x;
    if (slot >= end) return;
    const std::uint32_t i = clusterParticle[slot];
    const Vec3 p = position[i];
    const float r = radius[i];
    const BillboardFrame f = frames[i];
    const Vec3 a = r * f.right, b = r * f.up;
    Vec3* v = vertices + 4 * std::size_t(slot);
    v[0] = p - a - b;
    v[1] = p + a - b;
    v[2] = p + a + b;
    v[3] = p - a + b;
}

}  // namespace

void expandBillboards(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                      const float* radius, const BillboardFrame* frames, Vec3* vertices, cudaStream_t stream) {
    if (end <= begin) return;
    const unsigned threads = 256, blocks = (end - begin + threads - 1) / threads;
    expandBillboardsKernel<<<blocks, threads, 0, stream>>>(clusterParticle, begin, end, position, radius, frames, vertices);
}

}  // namespace accretion::twin
