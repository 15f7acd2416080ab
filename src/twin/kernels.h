#pragma once
// The twin's CUDA kernels (kernels.cu), launched on a stream.
#include <cstdint>

#include <cuda_runtime.h>
#include <optix_types.h>

#include "accretion/geometry/billboard.h"

namespace accretion::twin {

/// Billboard corners (4 per particle, in cluster order: slot s of
/// clusterParticle) for slots [begin, end), as the CPU's BLAS build forms
/// them: p -+ r right -+ r up.
void expandBillboards(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                      const float* radius, const BillboardFrame* frames, Vec3* vertices, cudaStream_t stream);

/// Sphere centres and radii (one per particle, in cluster order) for slots [begin, end).
void expandSpheres(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end, const Vec3* position,
                   const float* radius, Vec3* centres, float* radii, cudaStream_t stream);

/// The boxes of the billboards (one per particle, in cluster order) for
/// slots [begin, end): p -+ r (|right| + |up|) per axis, widened by one float
/// step so that the intersection program sees every edge hit.
void expandBillboardBoxes(const std::uint32_t* clusterParticle, std::uint32_t begin, std::uint32_t end,
                          const Vec3* position, const float* radius, const BillboardFrame* frames, OptixAabb* boxes,
                          cudaStream_t stream);

/// One TLAS instance per particle of the unit billboard (corners -+1, -+1 in
/// its plane): the transform [r right | r up | right x up | p], instance id i.
void writeInstances(std::uint32_t count, const Vec3* position, const float* radius, const BillboardFrame* frames,
                    OptixTraversableHandle unitBillboard, OptixInstance* instances, cudaStream_t stream);

}  // namespace accretion::twin
