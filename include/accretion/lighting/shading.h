#pragma once
#include <algorithm>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/geometry/shading_point.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// One light's unshadowed term f_j(x, w_i) I_i G_i(x) and the segment to it.
struct LightTerm {
    Vec3 value;   ///< f I G (RGB), > 0 in some channel when valid
    Vec3 w;       ///< unit direction x -> p_i (arbitrary when dist = 0)
    float dist;   ///< d_i = |p_i - x|
};

/// docs/MODEL.md section 3: G_i = cos_i / max(d_i^2, dmin_i^2); lambert and sphere:
/// f = rho / pi, cos_i = max(0, n . w_i); isotropic: f = rho / (4 pi), cos_i = 1.
/// Returns false when the term is zero (so no shadow ray is needed).
template <ShadingModel M>
[[gnu::always_inline]] ACC_HD inline bool evalLight(const ShadingPoint& sp, const Vec3& p, const Vec3& I, float dmin2, LightTerm& out) {
    const Vec3 delta = (p - sp.centre) - sp.local;  // receiver-relative: exact to the inputs' rounding
    const float d2 = glm::dot(delta, delta);
    const float d = std::sqrt(d2);
    float cosTerm, f;
    if constexpr (M == ShadingModel::isotropic) {
        cosTerm = 1.0f;
        f = kInv4Pi;
        out.w = d > 0.0f ? delta / d : sp.n;
    } else {
        if (!(d > 0.0f)) return false;
        out.w = delta / d;
        cosTerm = glm::dot(sp.n, out.w);
        if (!(cosTerm > 0.0f)) return false;
        f = kInvPi;
    }
    const float G = cosTerm / (d2 < dmin2 ? dmin2 : d2);  // std::max(d2, dmin2), also on the device
    out.value = (f * G) * sp.rho * I;
    out.dist = d;
    return out.value.x > 0.0f || out.value.y > 0.0f || out.value.z > 0.0f;
}

/// Runtime dispatch of evalLight (tests, cold paths).
inline bool evalLight(ShadingModel m, const ShadingPoint& sp, const Vec3& p, const Vec3& I, float dmin2, LightTerm& out) {
    switch (m) {
    case ShadingModel::lambert: return evalLight<ShadingModel::lambert>(sp, p, I, dmin2, out);
    case ShadingModel::sphere: return evalLight<ShadingModel::sphere>(sp, p, I, dmin2, out);
    case ShadingModel::isotropic: return evalLight<ShadingModel::isotropic>(sp, p, I, dmin2, out);
    }
    return false;
}

}  // namespace accretion
