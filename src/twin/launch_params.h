#pragma once
// What every OptiX program and CUDA kernel of the twin reads: one struct,
// copied to the device per launch. Host and device see the same layout.
#include <cstdint>

#include <optix_types.h>

#include "accretion/geometry/billboard.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/scene/settings.h"

namespace accretion::twin {

/// Ray types (SBT hit-group records per geometry: stride 2).
enum RayType : unsigned { kPrimaryRay = 0, kShadowRay = 1, kRayTypes = 2 };

/// Counters of one launch, summed with one atomic per thread.
struct LaunchCounters {
    unsigned long long rays = 0;         ///< optixTrace / optixTraverse calls
    unsigned long long anyHits = 0;      ///< any-hit invocations
    unsigned long long occluded = 0;     ///< shadow rays that found a blocker
    unsigned long long lightTerms = 0;   ///< unshadowed terms evaluated
};

struct LaunchParams {
    OptixTraversableHandle tlas = 0;
    Camera camera;                       ///< frame coordinates (origin at the first camera)
    ShadingModel model = ShadingModel::lambert;
    bool discAlpha = false;              ///< the disc alpha test (any-hit) on every ray
    bool shadows = true;                 ///< shading.visibility

    // Particles, frame coordinates (struct-of-arrays, as on the CPU).
    std::uint32_t particleCount = 0;
    const Vec3* position = nullptr;
    const Vec3* emission = nullptr;
    const Vec3* albedo = nullptr;
    const float* radius = nullptr;
    const float* dmin2 = nullptr;        ///< max(r_i, dmin)^2
    const BillboardFrame* frames = nullptr;

    // Clusters: BLAS c (TLAS instance id c) holds particles
    // clusterParticle[clusterOffset[c] ..], two triangles each.
    const std::uint32_t* clusterParticle = nullptr;
    const std::uint32_t* clusterOffset = nullptr;

    // Outputs.
    GBufferTexel* gbuffer = nullptr;     ///< width x height
    Vec3* Lr = nullptr;                  ///< width x height
    LaunchCounters* counters = nullptr;
};

/// The particle of a hit: instance (cluster) and primitive (2 per particle).
ACC_HD inline std::uint32_t hitParticle(const LaunchParams& p, unsigned instance, unsigned primitive) {
    return p.clusterParticle[p.clusterOffset[instance] + (primitive >> 1)];
}

}  // namespace accretion::twin
