#pragma once
// The twin's CUDA kernels (kernels.cu), launched on a stream.
#include <cstdint>

#include <cuda_runtime.h>

#include "accretion/geometry/billboard.h"

namespace accretion::twin {

/// Billboard corners (4 per particle, in cluster order: slot s of
/// clusterParticle) for slots [begin, end), as the CPU's BLAS build forms
/// them: p -+ r right -+ r up.
void expandBillboards(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                      const float* radius, const BillboardFrame* frames, Vec3* vertices, cudaStream_t stream);

}  // namespace accretion::twin
