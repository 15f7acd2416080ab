#pragma once
// What the CPU's pass bridges share (restir's, the voxel cache's,
// particle_split's): a shadow ray traced and counted, a pass's items run on
// every core with per-thread counters, and the dispatch of the frame's
// shading model, primitive and counting mode to the code compiled for
// them. Internal to src/render/.
#include <cstddef>
#include <cstdint>
#include <functional>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/render/estimators.h"
#include "accretion/render/visibility.h"

namespace accretion {

/// One shadow ray on the CPU toward light i of `lights` through `bvh`:
/// counted (c.shadowRays) and its traversal recorded.
template <Primitive P, bool Count>
bool countedShadowRay(const ParticleBvh& bvh, const VisibilityOptions& vis, const LightArrays& lights, const ShadingPoint& sp,
                      std::uint32_t i, const LightTerm& t, LightingCounters& c, Recorder<Count>& rec) {
    ++c.shadowRays;
    RayCounters rc;
    const PackedLight& l = lights.packed[i];
    const bool seen = visible<P>(bvh, vis, sp, i, l.position, l.radius, t, rec.rayCounters(rc));
    rec.ray(rc);
    return seen;
}

/// A G-buffer texel read by a counted thread: its bytes and, for a hit,
/// its branch key (the particle's type and cluster).
template <bool Count>
const GBufferTexel& recordedTexel(Recorder<Count>& rec, const GBufferTexel& g, const Particles& particles, const ParticleBvh& bvh) {
    if constexpr (Count) {
        rec.read(gpu_layout::kGBufferTexel);
        if (g.hit()) rec.shade(true, particles.type[g.particle], bvh.clusterOf(g.particle));
    }
    return g;
}

/// The item passes' one parallel loop, compiled once (cpu_passes.cpp):
/// range(begin, end, counters) over [0, n) in tasks of `grain` items on
/// every core, each thread with its own counters; returns them summed
/// (integers: the same whatever the threads).
LightingCounters runItemRanges(std::size_t n, std::size_t grain,
                               const std::function<void(std::size_t, std::size_t, LightingCounters&)>& range);

/// item(k, counters) for k in [0, n) on every core, `grain` items a task,
/// each thread adding to its own counters; returns them summed.
template <class Item>
LightingCounters forEachItemParallel(std::size_t n, std::size_t grain, Item&& item) {
    return runItemRanges(n, grain, [&](std::size_t begin, std::size_t end, LightingCounters& c) {
        for (std::size_t k = begin; k != end; ++k) item(k, c);
    });
}

/// fn.template operator()<P, Count>() for the primitive and counting mode.
template <class Fn>
LightingCounters withPrimitiveAndCount(Primitive primitive, bool count, Fn&& fn) {
    const bool spheres = primitive == Primitive::sphere;
    if (count)
        return spheres ? fn.template operator()<Primitive::sphere, true>() : fn.template operator()<Primitive::billboard, true>();
    return spheres ? fn.template operator()<Primitive::sphere, false>() : fn.template operator()<Primitive::billboard, false>();
}

/// fn.template operator()<SM>() for the shading model.
template <class Fn>
LightingCounters withShadingModel(ShadingModel model, Fn&& fn) {
    switch (model) {
    case ShadingModel::lambert: return fn.template operator()<ShadingModel::lambert>();
    case ShadingModel::sphere: return fn.template operator()<ShadingModel::sphere>();
    case ShadingModel::isotropic: return fn.template operator()<ShadingModel::isotropic>();
    }
    return LightingCounters{};
}

}  // namespace accretion
