#include "accretion/geometry/particle_bvh.h"

#include <chrono>
#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

#include "accretion/core/error.h"
#include "accretion/geometry/camera.h"

namespace accretion {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

inline constexpr std::uint64_t kNoKey = ~std::uint64_t(0);

/// Every query's context: the counters of the ray (null unless counting)
/// and, for occlusion queries, the keys (cluster << 32 | primitive) of the
/// particles excluded by identity.
struct QueryContext {
    RTCIntersectContext base;
    RayCounters* counters;
    std::uint64_t exclude[2];
};

QueryContext queryContext(RayCounters* counters, std::uint64_t receiver = kNoKey, std::uint64_t light = kNoKey) {
    QueryContext c;
    rtcInitIntersectContext(&c.base);
    c.counters = counters;
    c.exclude[0] = receiver;
    c.exclude[1] = light;
    return c;
}

/// The disc alpha test of candidate hit i (an any-hit): false rejects it.
/// With an opacity micromap, opaque and transparent micro-triangles are
/// decided without the any-hit (nor its count).
inline bool passesAlpha(const AlphaTest& alpha, Vec2 uv, RayCounters* counters) {
    if (alpha.omm) {
        if (counters) ++counters->ommLookups;
        Vec2 bary;
        const unsigned tri = quadTriangle(uv, bary);
        const OmmState s = alpha.omm->lookup(tri, bary.x, bary.y);
        if (s == OmmState::opaque) return true;
        if (s == OmmState::transparent) return false;
    }
    if (counters) {
        ++counters->anyHits;
        ++counters->candidates;
    }
    return insideDisc(uv);
}

/// Embree's quad parametrisation is the billboard's uv.
inline Vec2 hitUv(const RTCFilterFunctionNArguments* args, unsigned i) {
    return Vec2(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
}

/// Closest-hit queries on disc-alpha billboards: the alpha test.
void discAlphaFilter(const RTCFilterFunctionNArguments* args) {
    const auto* alpha = static_cast<const AlphaTest*>(args->geometryUserPtr);
    RayCounters* counters = reinterpret_cast<const QueryContext*>(args->context)->counters;
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] == -1 && !passesAlpha(*alpha, hitUv(args, i), counters)) args->valid[i] = 0;
}

/// Occlusion queries: the receiver and the light are excluded by identity
/// (docs/MODEL.md section 3), then (Alpha) the alpha test of the other candidates.
/// The identity is the hit's (instance, primitive) key, so that the filter
/// reads nothing but its arguments (a particle-index lookup here was a cache
/// miss on most calls).
template <bool Alpha>
void occlusionFilter(const RTCFilterFunctionNArguments* args) {
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        const std::uint64_t key = std::uint64_t(RTCHitN_instID(args->hit, args->N, i, 0)) << 32 |
                                  RTCHitN_primID(args->hit, args->N, i);
        if (key == context->exclude[0] || key == context->exclude[1]) args->valid[i] = 0;
        else if constexpr (Alpha) {
            if (!passesAlpha(*static_cast<const AlphaTest*>(args->geometryUserPtr), hitUv(args, i), context->counters))
                args->valid[i] = 0;
        }
    }
}

/// The counting TLAS: one user-geometry primitive per cluster, bounded by
/// its BLAS; entering it counts one BLAS entry and traverses that BLAS.
void instanceBounds(const RTCBoundsFunctionArguments* args) {
    const auto* bvh = static_cast<const ParticleBvh*>(args->geometryUserPtr);
    const RTCBounds& b = bvh->blasBounds(args->primID);
    args->bounds_o->lower_x = b.lower_x;
    args->bounds_o->lower_y = b.lower_y;
    args->bounds_o->lower_z = b.lower_z;
    args->bounds_o->upper_x = b.upper_x;
    args->bounds_o->upper_y = b.upper_y;
    args->bounds_o->upper_z = b.upper_z;
}

/// The instance's box test, as GPU traversal does before entering a BLAS
/// (Embree may call a leaf's callbacks without testing each primitive's box);
/// `entry`, when given, receives where the ray enters the box (tnear if inside).
bool overlapsBounds(const RTCBounds& b, const float org[3], const float dir[3], float tnear, float tfar,
                    float* entry = nullptr) {
    float t;
    if (!boxEntry(b, Vec3(org[0], org[1], org[2]), Vec3(1.0f / dir[0], 1.0f / dir[1], 1.0f / dir[2]), tnear, tfar, t))
        return false;
    if (entry) *entry = t;
    return true;
}

/// The nearer of o + t d's crossings of the sphere (p, r) within [tnear, tfar].
bool hitSphere(const Vec3& o, const Vec3& d, float tnear, float tfar, const Vec3& p, float r, float& t) {
    const Vec3 oc = o - p;
    const float a = glm::dot(d, d), h = glm::dot(d, oc), c = glm::dot(oc, oc) - r * r;
    const float disc = h * h - a * c;
    if (!(disc >= 0.0f)) return false;
    const float s = std::sqrt(disc), t0 = (-h - s) / a, t1 = (-h + s) / a;
    t = t0 >= tnear && t0 <= tfar ? t0 : t1;
    return t >= tnear && t <= tfar;
}

/// A box primitive's bounds: the billboard's quad or the sphere.
void boxBounds(const RTCBoundsFunctionArguments* args) {
    const auto* blas = static_cast<const BoxBlas*>(args->geometryUserPtr);
    const BoxPrimitive& b = blas->prims[args->primID];
    const Vec3 e = blas->sphere ? Vec3(b.r) : billboardExtent(b.r, blas->frames[blas->members[args->primID]]);
    *args->bounds_o = {b.p.x - e.x, b.p.y - e.y, b.p.z - e.z, 0.0f, b.p.x + e.x, b.p.y + e.y, b.p.z + e.z, 0.0f};
}

/// A ray reaching box `prim` of `blas`. Counting, the box is tested first,
/// as GPU traversal tests each box before it calls the primitive's program
/// (Embree may call a leaf's primitives without), and an entered box counts
/// as an intersection-program invocation, or for the instances layout as a
/// BLAS (instance) entry of one level; the test decides the count only, so
/// renders skip it. Then the billboard's or sphere's own test and, for
/// instances, the alpha test of the any-hit (the aabbs layout's program
/// tests alpha itself). True with t and uv of a hit in [tnear, tfar].
bool hitBox(const BoxBlas& blas, unsigned prim, const float org[3], const float dir[3], float tnear, float tfar,
            RayCounters* counters, float& t, Vec2& uv) {
    const BoxPrimitive& b = blas.prims[prim];
    const BillboardFrame& f = blas.frames[blas.members[prim]];
    if (counters) {
        const Vec3 e = blas.sphere ? Vec3(b.r) : billboardExtent(b.r, f);
        const RTCBounds box{b.p.x - e.x, b.p.y - e.y, b.p.z - e.z, 0.0f, b.p.x + e.x, b.p.y + e.y, b.p.z + e.z, 0.0f};
        if (!overlapsBounds(box, org, dir, tnear, tfar)) return false;
        if (blas.instances) {
            ++counters->blasEntries;
            ++counters->blasLevels;  // two triangles: one level
        } else {
            ++counters->intersections;
        }
    }
    const Vec3 o(org[0], org[1], org[2]), d(dir[0], dir[1], dir[2]);
    if (blas.sphere) {
        uv = Vec2(0.0f);
        return hitSphere(o, d, tnear, tfar, b.p, b.r, t);
    }
    const bool alphaInProgram = blas.disc && !blas.instances;
    if (!intersectBillboard(o, d, tnear, tfar, b.p, b.r, f, alphaInProgram, t, uv)) return false;
    return !(blas.disc && blas.instances) || passesAlpha(*blas.alpha, uv, counters);
}

void boxIntersect(const RTCIntersectFunctionNArguments* args) {
    ACC_CHECK(args->N == 1);  // rtcIntersect1 only (intersect8 traces these one ray at a time)
    if (args->valid[0] != -1) return;
    const auto* blas = static_cast<const BoxBlas*>(args->geometryUserPtr);
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const float org[3] = {rh->ray.org_x, rh->ray.org_y, rh->ray.org_z}, dir[3] = {rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z};
    float t;
    Vec2 uv;
    if (!hitBox(*blas, args->primID, org, dir, rh->ray.tnear, rh->ray.tfar,
                reinterpret_cast<const QueryContext*>(args->context)->counters, t, uv))
        return;
    rh->ray.tfar = t;
    rh->hit.u = uv.x;
    rh->hit.v = uv.y;
    rh->hit.Ng_x = rh->hit.Ng_y = 0.0f;
    rh->hit.Ng_z = 1.0f;
    rh->hit.primID = args->primID;
    rh->hit.geomID = args->geomID;
    rh->hit.instID[0] = args->context->instID[0];
}

void boxOccluded(const RTCOccludedFunctionNArguments* args) {
    ACC_CHECK(args->N == 1);
    if (args->valid[0] != -1) return;
    const auto* blas = static_cast<const BoxBlas*>(args->geometryUserPtr);
    const auto* context = reinterpret_cast<const QueryContext*>(args->context);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    const float org[3] = {ray->org_x, ray->org_y, ray->org_z}, dir[3] = {ray->dir_x, ray->dir_y, ray->dir_z};
    float t;
    Vec2 uv;
    if (!hitBox(*blas, args->primID, org, dir, ray->tnear, ray->tfar, context->counters, t, uv)) return;
    // The identity exclusion (the any-hit's test): the receiver's and the
    // light's own primitives are not blockers.
    const std::uint64_t key = std::uint64_t(args->context->instID[0]) << 32 | args->primID;
    if (key == context->exclude[0] || key == context->exclude[1]) return;
    ray->tfar = -std::numeric_limits<float>::infinity();
}

void instanceIntersect(const RTCIntersectFunctionNArguments* args) {
    if (args->N != 1 || args->valid[0] != -1) return;
    const auto* bvh = static_cast<const ParticleBvh*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const float org[3] = {ray->ray.org_x, ray->ray.org_y, ray->ray.org_z}, dir[3] = {ray->ray.dir_x, ray->ray.dir_y, ray->ray.dir_z};
    if (!overlapsBounds(bvh->blasBounds(args->primID), org, dir, ray->ray.tnear, ray->ray.tfar)) return;
    if (RayCounters* c = reinterpret_cast<QueryContext*>(args->context)->counters;
        c && bvh->settings().layout != AccelLayout::instances) {  // instances: each box counts its own entry
        ++c->blasEntries;
        c->blasLevels += bvh->blasLevels(args->primID);
    }
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const RTCHit saved = rh->hit;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    args->context->instID[0] = args->primID;
    rtcIntersect1(bvh->blas(args->primID), args->context, rh);
    args->context->instID[0] = RTC_INVALID_GEOMETRY_ID;
    if (rh->hit.geomID == RTC_INVALID_GEOMETRY_ID) rh->hit = saved;
    else rh->hit.instID[0] = args->primID;
}

void instanceOccluded(const RTCOccludedFunctionNArguments* args) {
    if (args->N != 1 || args->valid[0] != -1) return;
    const auto* bvh = static_cast<const ParticleBvh*>(args->geometryUserPtr);
    const auto* ray = reinterpret_cast<const RTCRay*>(args->ray);
    const float org[3] = {ray->org_x, ray->org_y, ray->org_z}, dir[3] = {ray->dir_x, ray->dir_y, ray->dir_z};
    if (!overlapsBounds(bvh->blasBounds(args->primID), org, dir, ray->tnear, ray->tfar)) return;
    if (RayCounters* c = reinterpret_cast<QueryContext*>(args->context)->counters;
        c && bvh->settings().layout != AccelLayout::instances) {  // instances: each box counts its own entry
        ++c->blasEntries;
        c->blasLevels += bvh->blasLevels(args->primID);
    }
    args->context->instID[0] = args->primID;
    rtcOccluded1(bvh->blas(args->primID), args->context, reinterpret_cast<RTCRay*>(args->ray));
    args->context->instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/// The probe's queries. Counting: every particle's box the ray enters, no
/// hit reported, so that Embree visits each along the segment, and of them
/// those entered before `blockedAt`. Blocker search: the nearest particle
/// (not excluded) whose primitive the ray hits, reported as a hit so that
/// Embree culls the boxes behind it.
struct ProbeContext {
    RTCIntersectContext base;
    const ProbeData* probe;
    BoxesCrossed crossed;
    float blockedAt;
    bool blockers;
    std::uint32_t exclude[2];
};

/// Whether o + t d hits particle i's primitive (its sphere, or its
/// billboard with the alpha test) within [tnear, tfar], and where.
bool hitProbePrimitive(const ProbeData& probe, unsigned i, const Vec3& o, const Vec3& d, float tnear, float tfar, float& t) {
    const BoxPrimitive& b = probe.prims[i];
    Vec2 uv;
    return probe.sphere ? hitSphere(o, d, tnear, tfar, b.p, b.r, t)
                        : intersectBillboard(o, d, tnear, tfar, b.p, b.r, probe.frames[i], probe.disc, t, uv);
}

void probeBounds(const RTCBoundsFunctionArguments* args) {
    *args->bounds_o = static_cast<const ProbeData*>(args->geometryUserPtr)->boxes[args->primID];
}

void probeIntersect(const RTCIntersectFunctionNArguments* args) {
    if (args->N != 1 || args->valid[0] != -1) return;
    auto* context = reinterpret_cast<ProbeContext*>(args->context);
    const ProbeData& probe = *context->probe;
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    const RTCRay& ray = rh->ray;
    const unsigned i = args->primID;
    const float org[3] = {ray.org_x, ray.org_y, ray.org_z}, dir[3] = {ray.dir_x, ray.dir_y, ray.dir_z};
    // Embree hands over every primitive of a leaf it enters: the ray's own box test first.
    float entry;
    if (!overlapsBounds(probe.boxes[i], org, dir, ray.tnear, ray.tfar, &entry)) return;
    if (!context->blockers) {
        ++context->crossed.whole;
        context->crossed.untilBlocker += entry <= context->blockedAt;
        return;
    }
    if (i == context->exclude[0] || i == context->exclude[1]) return;
    float t;
    if (!hitProbePrimitive(probe, i, Vec3(org[0], org[1], org[2]), Vec3(dir[0], dir[1], dir[2]), ray.tnear, ray.tfar, t))
        return;
    rh->ray.tfar = t;
    rh->hit.geomID = 0;
    rh->hit.primID = i;
}

RTCBuildQuality sceneQuality(BuildPolicy p) {
    return p == BuildPolicy::fast_trace ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_LOW;
}

/// An Embree ray from o along d over [tnear, tfar], every mask bit set.
RTCRay embreeRay(const Vec3& o, const Vec3& d, float tnear, float tfar) {
    return RTCRay{.org_x = o.x, .org_y = o.y, .org_z = o.z, .tnear = tnear, .dir_x = d.x, .dir_y = d.y, .dir_z = d.z,
                  .time = 0.0f, .tfar = tfar, .mask = ~0u, .id = 0, .flags = 0};
}

}  // namespace

ParticleBvh::ParticleBvh(const EmbreeDevice& device, const GeometrySettings& settings, const GpuSettings& gpu)
    : device_(device), settings_(settings), counting_(gpu.counters) {
    if (settings.alpha == AlphaMode::disc && gpu.omm != OmmMode::off)
        omm_ = std::make_unique<OpacityMicromap>(gpu.omm_level, gpu.omm == OmmMode::four_state);
    alpha_.omm = omm_.get();
}

ParticleBvh::~ParticleBvh() { releaseBlas(); }

void ParticleBvh::releaseBlas() {
    // The TLAS first (its instances hold the BLAS), then the BLAS in
    // parallel: freeing a frame's structures serially costs ~5 ms at 100K.
    if (tlas_) rtcReleaseScene(tlas_);
    tlas_ = nullptr;
    if (countingTlas_) rtcReleaseScene(countingTlas_);
    countingTlas_ = nullptr;
    if (probe_) rtcReleaseScene(probe_);
    probe_ = nullptr;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blas_.size(), 16), [&](const auto& r) {
        for (std::size_t c = r.begin(); c != r.end(); ++c) rtcReleaseScene(blas_[c]);
    });
    blas_.clear();
    geometry_.clear();
}

void ParticleBvh::buildBlas(std::size_t c, const Particles& particles, bool create) {
    if (create) createBlas(c);
    writePrimitives(c, particles, create);
}

/// Cluster c's Embree scene and geometry (quads, points or user boxes), with
/// the filters that exclude a query's receiver and light by identity.
void ParticleBvh::createBlas(std::size_t c) {
    const std::size_t n = clusters_.members(c).size();
    const bool billboards = settings_.primitive == Primitive::billboard;
    RTCGeometry geom;
    RTCScene scene = rtcNewScene(device_.get());
    rtcSetSceneBuildQuality(scene, sceneQuality(settings_.build));
    // watertight: Embree's robust mode, so that no ray slips between a
    // quad's two triangles along its diagonal (~30% slower shadow rays).
    rtcSetSceneFlags(scene, (settings_.watertight ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE) |
                                (settings_.build == BuildPolicy::refit ? RTC_SCENE_FLAG_DYNAMIC : RTC_SCENE_FLAG_NONE));
    // Billboards are Embree quads (one primitive, builds ~1.5x faster than
    // two triangles); the GPU's two triangles are recovered from uv.
    const bool boxes = boxPrimitives();
    geom = rtcNewGeometry(device_.get(), boxes        ? RTC_GEOMETRY_TYPE_USER
                                         : billboards ? RTC_GEOMETRY_TYPE_QUAD
                                                      : RTC_GEOMETRY_TYPE_SPHERE_POINT);
    if (settings_.build == BuildPolicy::refit) rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_REFIT);
    if (boxes) {
        BoxBlas& b = boxBlas_[c];
        b = {boxes_.data() + clusters_.offset[c], clusters_.particle.data() + clusters_.offset[c], frames_.data(), &alpha_,
             billboards && settings_.alpha == AlphaMode::disc, !billboards, settings_.layout == AccelLayout::instances};
        rtcSetGeometryUserPrimitiveCount(geom, static_cast<unsigned>(n));
        rtcSetGeometryUserData(geom, &b);
        rtcSetGeometryBoundsFunction(geom, &boxBounds, &b);
        rtcSetGeometryIntersectFunction(geom, &boxIntersect);
        rtcSetGeometryOccludedFunction(geom, &boxOccluded);
    } else if (billboards) {
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(float) * 3, 4 * n);
        auto* idx = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, sizeof(std::uint32_t) * 4, n));
        for (std::uint32_t k = 0; k < 4 * n; ++k) idx[k] = k;
    } else {
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, sizeof(float) * 4, n);
    }
    // Every occlusion query excludes its receiver and light by identity
    // (box primitives: in their own occlusion function).
    const bool alpha = billboards && settings_.alpha == AlphaMode::disc;
    if (boxes) {
    } else if (alpha) {
        rtcSetGeometryUserData(geom, const_cast<AlphaTest*>(&alpha_));
        rtcSetGeometryIntersectFilterFunction(geom, &discAlphaFilter);
    }
    if (!boxes) rtcSetGeometryOccludedFilterFunction(geom, alpha ? &occlusionFilter<true> : &occlusionFilter<false>);
    rtcAttachGeometryByID(scene, geom, 0);
    rtcReleaseGeometry(geom);  // the scene keeps it
    blas_[c] = scene;
    geometry_[c] = geom;
}

/// Cluster c's primitives from the particles (its buffers written, the
/// geometry and scene committed); `create`: its members' places recorded.
void ParticleBvh::writePrimitives(std::size_t c, const Particles& particles, bool create) {
    const auto members = clusters_.members(c);
    const std::size_t n = members.size();
    const bool billboards = settings_.primitive == Primitive::billboard;
    const RTCGeometry geom = geometry_[c];
    const bool boxes = boxPrimitives();
    auto* vtx = boxes ? nullptr : static_cast<float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    BoxPrimitive* box = boxes ? boxes_.data() + clusters_.offset[c] : nullptr;
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t i = members[k];
        if (k + 8 < n) {  // members are scattered over the particle arrays
            const std::uint32_t ahead = members[k + 8];
            __builtin_prefetch(&particles.position[ahead]);
            __builtin_prefetch(&particles.radius[ahead]);
            if (billboards) __builtin_prefetch(&frames_[ahead]);
            if (create) __builtin_prefetch(&where_[ahead], 1);
        }
        if (create) where_[i] = std::uint64_t(c) << 32 | k;
        const Vec3 p = particles.position[i];
        const float r = particles.radius[i];
        if (boxes) {
            box[k] = {p, r};
        } else if (billboards) {
            const BillboardFrame& f = frames_[i];
            const Vec3 a = r * f.right, b = r * f.up;
            const Vec3 corners[4] = {p - a - b, p + a - b, p + a + b, p - a + b};
            for (int j = 0; j < 4; ++j)
                for (int d = 0; d < 3; ++d) vtx[12 * k + 3 * j + d] = corners[j][d];
        } else {
            vtx[4 * k + 0] = p.x;
            vtx[4 * k + 1] = p.y;
            vtx[4 * k + 2] = p.z;
            vtx[4 * k + 3] = r;
        }
    }
    if (!create && !boxes) rtcUpdateGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(geom);
    rtcCommitScene(blas_[c]);
}

void ParticleBvh::buildTlas() {
    if (tlas_) rtcReleaseScene(tlas_);
    tlas_ = rtcNewScene(device_.get());
    rtcSetSceneBuildQuality(tlas_, sceneQuality(settings_.build));
    if (settings_.watertight) rtcSetSceneFlags(tlas_, RTC_SCENE_FLAG_ROBUST);  // conservative box tests
    const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    for (std::size_t c = 0; c < blas_.size(); ++c) {
        RTCGeometry inst = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(inst, blas_[c]);
        rtcSetGeometryTransform(inst, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
        rtcCommitGeometry(inst);
        rtcAttachGeometryByID(tlas_, inst, static_cast<unsigned>(c));
        rtcReleaseGeometry(inst);
    }
    rtcCommitScene(tlas_);
}

void ParticleBvh::buildCountingTlas() {
    if (countingTlas_) rtcReleaseScene(countingTlas_);
    countingTlas_ = rtcNewScene(device_.get());
    rtcSetSceneBuildQuality(countingTlas_, sceneQuality(settings_.build));
    blasBounds_.resize(blas_.size());
    for (std::size_t c = 0; c < blas_.size(); ++c) rtcGetSceneBounds(blas_[c], &blasBounds_[c]);
    RTCGeometry g = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(blas_.size()));
    rtcSetGeometryUserData(g, this);
    rtcSetGeometryBoundsFunction(g, &instanceBounds, this);
    rtcSetGeometryIntersectFunction(g, &instanceIntersect);
    rtcSetGeometryOccludedFunction(g, &instanceOccluded);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(countingTlas_, g, 0);
    rtcReleaseGeometry(g);
    rtcCommitScene(countingTlas_);
}

void ParticleBvh::buildProbe(const Particles& particles, bool refit) {
    const std::size_t n = particles.size();
    probeBoxes_.resize(n);
    probePrims_.resize(n);
    const bool billboards = settings_.primitive == Primitive::billboard;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3 p = particles.position[i];
            const float rad = particles.radius[i];
            // The quad's box (its corners p +- a +- b), or the sphere's.
            const Vec3 h = billboards ? billboardExtent(rad, frames_[i]) : Vec3(rad);
            probeBoxes_[i] = {p.x - h.x, p.y - h.y, p.z - h.z, 0.0f, p.x + h.x, p.y + h.y, p.z + h.z, 0.0f};
            probePrims_[i] = {p, rad};
        }
    });
    probeData_ = {probeBoxes_.data(), probePrims_.data(), frames_.data(), !billboards,
                  billboards && settings_.alpha == AlphaMode::disc};
    if (probe_) rtcReleaseScene(probe_);
    probe_ = rtcNewScene(device_.get());
    RTCGeometry g = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(n));
    rtcSetGeometryUserData(g, &probeData_);
    rtcSetGeometryBoundsFunction(g, &probeBounds, &probeData_);
    rtcSetGeometryIntersectFunction(g, &probeIntersect);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(probe_, g, 0);
    rtcReleaseGeometry(g);
    rtcCommitScene(probe_);
    if (refit && traversal_.primitives() == n) traversal_.refit(probeBoxes_);
    else traversal_.build(device_.get(), probeBoxes_);
}

BoxesCrossed ParticleBvh::boxesAlong(const Vec3& o, const Vec3& d, float tnear, float tfar, const Exclusion* occlusion) const {
    ProbeContext context;
    rtcInitIntersectContext(&context.base);
    context.probe = &probeData_;
    context.crossed = {};
    context.blockedAt = tfar;
    RTCRayHit rh;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    if (occlusion) {  // where the first blocker is
        context.blockers = true;
        context.exclude[0] = occlusion->receiver;
        context.exclude[1] = occlusion->light;
        rh.ray = embreeRay(o, d, tnear, tfar);
        rtcIntersect1(probe_, &context.base, &rh);
        context.blockedAt = rh.ray.tfar;
    }
    context.blockers = false;
    rh.ray = embreeRay(o, d, tnear, tfar);
    rtcIntersect1(probe_, &context.base, &rh);
    return context.crossed;
}

void ParticleBvh::build(const Particles& particles, const Camera& camera) {
    stats_ = BvhStats{};
    const std::size_t n = particles.size();
    // refit and partial keep the clusters (and BLAS objects) of the first build.
    const bool keep = (settings_.build == BuildPolicy::refit || settings_.build == BuildPolicy::partial) &&
                      !blas_.empty() && clusters_.particle.size() == n;
    const bool refit = keep && settings_.build == BuildPolicy::refit;

    auto t0 = std::chrono::steady_clock::now();
    if (!keep) {
        // The instances layout: one BLAS of boxes, each box one instance.
        const std::uint32_t target = settings_.layout == AccelLayout::instances ? std::numeric_limits<std::uint32_t>::max()
                                                                                : settings_.cluster_size;
        clusters_ = clusterParticles(particles.position, target);
        stats_.reclustered = true;
    }
    stats_.clusterSeconds = secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    frames_.resize(n);
    if (settings_.primitive == Primitive::billboard) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i)
                frames_[i] = billboardFrame(settings_.orientation, camera, particles.position[i], particles.velocity[i]);
        });
    } else {
        std::fill(frames_.begin(), frames_.end(), BillboardFrame{camera.right, camera.up});
    }
    if (!keep) {
        releaseBlas();
        blas_.assign(clusters_.count(), nullptr);
        geometry_.assign(clusters_.count(), nullptr);
        where_.resize(n);
        boxes_.assign(boxPrimitives() ? n : 0, BoxPrimitive{});
        boxBlas_.assign(boxPrimitives() ? clusters_.count() : 0, BoxBlas{});
    }
    // partial: a window of rebuild_fraction of the clusters, advancing round
    // robin frame by frame; the others keep last frame's (stale) geometry.
    const std::size_t C = clusters_.count();
    std::size_t first = 0, count = C;
    if (keep && settings_.build == BuildPolicy::partial) {
        count = std::min(C, static_cast<std::size_t>(std::ceil(settings_.rebuild_fraction * double(C))));
        first = partialCursor_ % std::max<std::size_t>(C, 1);
        partialCursor_ += count;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1), [&](const auto& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) buildBlas((first + k) % C, particles, !keep);
    });
    stats_.rebuiltClusters = count;
    device_.check("buildClusters (BLAS)");
    stats_.blasSeconds = secondsSince(t0);

    t0 = std::chrono::steady_clock::now();
    buildTlas();
    if (counting_) buildCountingTlas();
    device_.check("buildClusters (TLAS)");
    stats_.tlasSeconds = secondsSince(t0);
    if (counting_) buildProbe(particles, refit);  // counting's own structure: not the GPU's build, not timed as one

    stats_.refitted = refit;
    stats_.partial = keep && settings_.build == BuildPolicy::partial;
    stats_.clusters = clusters_.count();
    const bool triangles = settings_.primitive == Primitive::billboard && settings_.layout == AccelLayout::clusters;
    stats_.primitives = triangles ? 2 * n : n;
    stats_.triangles = triangles ? stats_.primitives : 0;
    stats_.embreeBytes = device_.bytesInUse();
    stats_.layout = describeLayout(settings_);
}

bool ParticleBvh::intersect(const Vec3& o, const Vec3& d, float tfar, SurfaceHit& hit, RayCounters* counters) const {
    QueryContext context = queryContext(counters);
    RTCRayHit rh;
    rh.ray = embreeRay(o, d, 0.0f, tfar);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(counters && countingTlas_ ? countingTlas_ : tlas_, &context.base, &rh);
    if (counters && probe_) {
        const BoxesCrossed n = boxesAlong(o, d, 0.0f, rh.ray.tfar);  // up to the hit: no blocker search
        counters->segmentBoxes += n.untilBlocker;
        counters->wholeSegmentBoxes += n.whole;
        counters->nodeVisits += traversal_.closestHit(o, d, 0.0f, tfar, [&](unsigned i, float t0, float t1, float& t) {
            return hitProbePrimitive(probeData_, i, o, d, t0, t1, t);
        });
    }
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    const std::uint32_t c = rh.hit.instID[0];
    const std::uint32_t local = rh.hit.primID;
    hit.cluster = c;
    hit.particle = clusters_.particle[clusters_.offset[c] + local];
    hit.t = rh.ray.tfar;
    hit.uv = Vec2(rh.hit.u, rh.hit.v);
    return true;
}

void ParticleBvh::intersect8(const Vec3& o, const Vec3* d, int n, SurfaceHit* hit, bool* found) const {
    if (boxPrimitives()) {  // their functions take one ray at a time
        for (int k = 0; k < n; ++k) found[k] = intersect(o, d[k], std::numeric_limits<float>::infinity(), hit[k]);
        return;
    }
    QueryContext context = queryContext(nullptr);
    alignas(32) int valid[8];
    alignas(32) RTCRayHit8 rh;
    for (int k = 0; k < 8; ++k) {
        valid[k] = k < n ? -1 : 0;
        const Vec3 dk = d[k < n ? k : 0];
        rh.ray.org_x[k] = o.x;
        rh.ray.org_y[k] = o.y;
        rh.ray.org_z[k] = o.z;
        rh.ray.dir_x[k] = dk.x;
        rh.ray.dir_y[k] = dk.y;
        rh.ray.dir_z[k] = dk.z;
        rh.ray.tnear[k] = 0.0f;
        rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
        rh.ray.time[k] = 0.0f;
        rh.ray.mask[k] = ~0u;
        rh.ray.id[k] = 0;
        rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, tlas_, &context.base, &rh);
    for (int k = 0; k < n; ++k) {
        found[k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
        if (!found[k]) continue;
        const std::uint32_t c = rh.hit.instID[0][k];
        hit[k].cluster = c;
        hit[k].particle = clusters_.particle[clusters_.offset[c] + rh.hit.primID[k]];
        hit[k].t = rh.ray.tfar[k];
        hit[k].uv = Vec2(rh.hit.u[k], rh.hit.v[k]);
    }
}

bool ParticleBvh::occluded(const Vec3& o, const Vec3& d, float tnear, float tfar, Exclusion exclude,
                           RayCounters* counters) const {
    QueryContext context = queryContext(counters, exclude.receiver == kNotExcluded ? kNoKey : where_[exclude.receiver],
                                        exclude.light == kNotExcluded ? kNoKey : where_[exclude.light]);
    RTCRay ray = embreeRay(o, d, tnear, tfar);
    rtcOccluded1(counters && countingTlas_ ? countingTlas_ : tlas_, &context.base, &ray);
    if (counters && probe_) {
        const BoxesCrossed n = boxesAlong(o, d, tnear, tfar, &exclude);
        counters->segmentBoxes += n.untilBlocker;
        counters->wholeSegmentBoxes += n.whole;
        counters->nodeVisits += traversal_.anyHit(o, d, tnear, tfar, [&](unsigned i, float t0, float t1, float& t) {
            return i != exclude.receiver && i != exclude.light && hitProbePrimitive(probeData_, i, o, d, t0, t1, t);
        });
    }
    return ray.tfar < 0.0f;
}

GeometrySettings cpuGeometry(const GeometrySettings& g, bool counting) {
    if (counting || g.cpu_layout == CpuLayout::gpu || g.build == BuildPolicy::partial) return g;
    GeometrySettings one = g;
    one.layout = AccelLayout::clusters;
    one.cluster_size = std::numeric_limits<std::uint32_t>::max();
    return one;
}

std::string describeLayout(const GeometrySettings& g) {
    const std::string what = g.primitive == Primitive::sphere ? "spheres" : "billboards";
    if (g.layout == AccelLayout::instances) return "one TLAS instance per particle (instances layout)";
    const std::string of = g.layout == AccelLayout::aabbs ? "procedural boxes of " + what : what;
    if (g.cluster_size == std::numeric_limits<std::uint32_t>::max()) return "one BVH of every particle (" + of + ")";
    return "BLAS per cluster of " + std::to_string(g.cluster_size) + " (" + of + ")";
}

AccelCounters ParticleBvh::accelCounters() const {
    AccelCounters a;
    const bool billboards = settings().primitive == Primitive::billboard && settings().layout == AccelLayout::clusters;
    a.particles = clusters_.particle.size();
    if (settings().layout == AccelLayout::instances) {  // one BLAS of the unit billboard, an instance per particle
        a.blasPrimitives = {2};
        a.tlasInstances = a.particles;
    } else {
        a.blasPrimitives.resize(clusters_.count());
        for (std::size_t c = 0; c < clusters_.count(); ++c)
            a.blasPrimitives[c] = static_cast<std::uint32_t>(clusters_.members(c).size()) * (billboards ? 2u : 1u);
        a.tlasInstances = clusters_.count();
    }
    a.embreeBytes = stats_.embreeBytes;
    if (omm_) {
        const OmmMemory m = ommMemory(*omm_, stats_.primitives / 2);
        a.omm = {true, omm_->level(), omm_->fourState(), omm_->count(OmmState::opaque),
                 omm_->count(OmmState::transparent), omm_->count(OmmState::unknown), m.sharedBytes, m.perTriangleBytes};
    }
    return a;
}

}  // namespace accretion
