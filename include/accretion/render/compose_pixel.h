#pragma once
#include <cmath>

#include "accretion/core/math.h"

namespace accretion {

/// composeImage's rule for a hit pixel (docs/MODEL.md section 3), shared with
/// the OptiX twin: Le = s_e I_j, L = Le + Lr. A float overflow never reaches
/// an output: when L is not finite, Le, L and Lr become 0 and it returns false
/// (the caller counts the rejection).
inline bool composeHit(float selfEmission, const Vec3& emission, Vec3& Lr, Vec3& Le, Vec3& L) {
    Le = selfEmission * emission;
    L = Le + Lr;
    if (std::isfinite(L.x + L.y + L.z)) return true;
    Le = L = Lr = Vec3(0.0f);
    return false;
}

}  // namespace accretion
