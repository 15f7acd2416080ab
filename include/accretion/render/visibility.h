#pragma once
#include <cmath>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/render/shadow_query.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// V(x, p_i): one occlusion query that stops at the first hit (counted into
/// `counters` when given: counting mode). A query with an empty interval
/// (a light at the receiver, or inside the offset rule's margins) sees it.
template <Primitive P>
inline bool visible(const ParticleBvh& bvh, const VisibilityOptions& v, const ShadingPoint& sp, std::uint32_t i,
                    const Vec3& p, float r, const LightTerm& t, RayCounters* counters = nullptr) {
    const ShadowQuery q = shadowQuery<P>(v, sp, i, p, r, t);
    if (!(q.tfar > q.tnear)) return true;
    const bool blocked = bvh.occluded(q.o, q.d, q.tnear, q.tfar, q.exclude, counters);
    if (counters) counters->misses += !blocked;
    return !blocked;
}

}  // namespace accretion
