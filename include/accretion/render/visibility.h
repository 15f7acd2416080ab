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

/// The shadow ray of V(x, p_i): origin, direction (unit) and far end; tfar
/// <= 0 when the light is too close for any ray (then V = 1).
struct ShadowRay {
    Vec3 o, d;
    float tfar;
};

template <Primitive P>
inline ShadowRay shadowRay(const ShadingPoint& sp, const LightTerm& light, float lightRadius, float eps) {
    float tfar;
    if constexpr (P == Primitive::sphere) tfar = (light.dist - lightRadius) * (1.0f - eps);
    else tfar = light.dist * (1.0f - eps);
    const Vec3 side = glm::dot(sp.ng, light.w) >= 0.0f ? sp.ng : -sp.ng;
    return {offsetRayOrigin(sp.x, side), light.w, tfar > 0.0f ? tfar : 0.0f};
}

/// V(x, p_i) of MODEL.md section 3: the segment from the (offset) receiver to
/// the light, ending short of the light's own geometry: billboards
/// t < d (1 - eps) (p_i lies on its own quad), spheres t < (d - r_i)(1 - eps).
/// One occlusion query that stops at the first hit (counted into `counters`
/// when given: counting mode).
template <Primitive P>
inline bool visible(const ParticleBvh& bvh, const ShadingPoint& sp, const LightTerm& light, float lightRadius, float eps,
                    RayCounters* counters = nullptr) {
    const ShadowRay r = shadowRay<P>(sp, light, lightRadius, eps);
    if (!(r.tfar > 0.0f)) return true;
    return !bvh.occluded(r.o, r.d, r.tfar, counters);
}

}  // namespace accretion
