#pragma once
#include <bit>
#include <cmath>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/render/shading.h"

namespace accretion {

/// Scale-aware ray origin offset (Waechter & Binder, "A Fast and Robust
/// Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6): move p
/// along n by a fixed number of float ulps, or by a fixed absolute amount
/// near the origin where ulps are tiny.
inline Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n) {
    constexpr float kOriginBand = 1.0f / 32.0f;
    constexpr float kFloatScale = 1.0f / 65536.0f;
    constexpr float kIntScale = 256.0f;
    Vec3 out;
    for (int k = 0; k < 3; ++k) {
        const auto ulps = static_cast<std::int32_t>(kIntScale * n[k]);
        const std::int32_t bits = std::bit_cast<std::int32_t>(p[k]) + (p[k] < 0.0f ? -ulps : ulps);
        out[k] = std::fabs(p[k]) < kOriginBand ? p[k] + kFloatScale * n[k] : std::bit_cast<float>(bits);
    }
    return out;
}

/// V(x, p_i) of MODEL.md section 3: the segment from the (offset) receiver to
/// the light, ending short of the light's own geometry: billboards
/// t < d (1 - eps) (p_i lies on its own quad), spheres t < (d - r_i)(1 - eps).
/// One occlusion query that stops at the first hit (counted into `counters`
/// when given: counting mode).
template <Primitive P>
inline bool visible(const ParticleBvh& bvh, const ShadingPoint& sp, const LightTerm& light, float lightRadius, float eps,
                    RayCounters* counters = nullptr) {
    float tfar;
    if constexpr (P == Primitive::sphere) tfar = (light.dist - lightRadius) * (1.0f - eps);
    else tfar = light.dist * (1.0f - eps);
    if (!(tfar > 0.0f)) return true;
    const Vec3 side = glm::dot(sp.ng, light.w) >= 0.0f ? sp.ng : -sp.ng;
    return !bvh.occluded(offsetRayOrigin(sp.x, side), light.w, tfar, counters);
}

}  // namespace accretion
