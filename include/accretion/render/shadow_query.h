#pragma once
// The shadow ray of V(x, p_i) under render.visibility_rule (docs/MODEL.md
// section 3): its interval and its exclusions. Shared by the CPU renderer and
// the OptiX twin (ACC_HD), so both trace the same rays.
#include <cstdint>
#include <cstring>

#include "accretion/core/math.h"
#include "accretion/geometry/exclusion.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Scale-aware ray origin offset (Waechter & Binder, "A Fast and Robust
/// Method for Avoiding Self-Intersection", Ray Tracing Gems ch. 6): move p
/// along n by a fixed number of float ulps, or by a fixed absolute amount
/// near the origin where ulps are tiny. Used only by the `offset` rule.
ACC_HD inline Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n) {
    constexpr float kOriginBand = 1.0f / 32.0f;
    constexpr float kFloatScale = 1.0f / 65536.0f;
    constexpr float kIntScale = 256.0f;
    Vec3 out;
    for (int k = 0; k < 3; ++k) {
        const auto ulps = static_cast<std::int32_t>(kIntScale * n[k]);
        std::int32_t bits;
        std::memcpy(&bits, &p[k], sizeof bits);
        bits += p[k] < 0.0f ? -ulps : ulps;
        float moved;
        std::memcpy(&moved, &bits, sizeof moved);
        out[k] = (p[k] < 0.0f ? -p[k] : p[k]) < kOriginBand ? p[k] + kFloatScale * n[k] : moved;
    }
    return out;
}

/// The visibility rule of every shadow ray of a frame (render.visibility_rule
/// and its offset_* parameters), read once from the settings.
struct VisibilityOptions {
    VisibilityRule rule = VisibilityRule::exact;
    OffsetOrigin origin = OffsetOrigin::tmin;
    float tmin = 1e-3f;
    FarEnd far = FarEnd::absolute;
    float margin = 1e-3f;

    static VisibilityOptions from(const RenderSettings& r) {
        return {r.visibility_rule, r.offset_origin, float(r.offset_tmin), r.offset_far, float(r.offset_far_margin)};
    }
};

/// One occlusion query: o + t d, t in [tnear, tfar], ignoring `exclude`.
struct ShadowQuery {
    Vec3 o, d;
    float tnear, tfar;
    Exclusion exclude;
};

/// The query of V(x, p_i) (docs/MODEL.md section 3) for receiver sp and light i
/// at p (radius r), whose unshadowed term t holds w and d.
///  - exact (the reference): the whole segment from x to p_i, with the
///    receiver's and the light's own primitives excluded by identity.
///  - offset (what GPU code does; a measured bias): no exclusion; the origin
///    moves by TMin along the ray, or off the surface (Waechter-Binder) with
///    the ray re-aimed at p_i from there; the far end stops short of the
///    light (of its sphere's near surface for spheres) by e (TMax = D - e)
///    or by a fraction (TMax = D (1 - e)).
template <Primitive P>
ACC_HD inline ShadowQuery shadowQuery(const VisibilityOptions& v, const ShadingPoint& sp, std::uint32_t i, const Vec3& p,
                                      float r, const LightTerm& t) {
    if (v.rule == VisibilityRule::exact) return {sp.x, t.w, 0.0f, t.dist, {sp.self, i}};
    ShadowQuery q{sp.x, t.w, 0.0f, t.dist, {}};
    if (v.origin == OffsetOrigin::tmin) {
        q.tnear = v.tmin;
    } else {
        q.o = offsetRayOrigin(sp.x, glm::dot(sp.ng, t.w) >= 0.0f ? sp.ng : -sp.ng);
        const Vec3 delta = p - q.o;
        const float d = glm::length(delta);
        if (d > 0.0f) q.d = delta / d;
        q.tfar = d;
    }
    float D = q.tfar;
    if constexpr (P == Primitive::sphere) D -= r;
    q.tfar = v.far == FarEnd::absolute ? D - v.margin : D * (1.0f - v.margin);
    return q;
}

}  // namespace accretion
