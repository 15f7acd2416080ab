// The twin's OptiX programs (compiled to OptiX-IR): the G-buffer raygen,
// the exact estimator's raygen, the uniform / power estimators' raygen,
// restir's shading raygens, the hit programs of its two ray types, and the
// billboard intersection program of the aabbs layout (which runs the disc
// alpha test itself, so that its hits need no any-hit for it).
//  - primary rays: closest hit; on disc-alpha billboards an any-hit runs the
//    alpha test;
//  - shadow rays (V(x, p_i), docs/MODEL.md section 3): an any-hit excludes the
//    receiver j and the light i by identity (the particle of the candidate's
//    instance and primitive; none under the offset rule), runs the alpha
//    test, and ends the search at the first accepted blocker; with opacity
//    micromaps a closest-hit reports that blocker for the exact re-test.
#include <optix.h>

#include "accretion/lighting/shading.h"
#include "accretion/render/light_estimates.h"
#include "accretion/render/sample_sums.h"
#include "accretion/render/shadow_query.h"
#include "launch_params.h"
#include "device_bridge.h"
#include "split_device.h"
#include "voxel_device.h"
#include "restir_device.h"

using namespace accretion;
using namespace accretion::twin;

extern "C" __constant__ LaunchParams params;

namespace {

// Shadow payload: 0 receiver, 1 light, 2 occluded, 3 any-hit count.
// Primary payload: 0 instance, 1 primitive, 2-3 barycentrics, 4 t (0xffffffff instance: miss).

/// The quad uv of the current billboard hit: from the triangle's
/// barycentrics, or the intersection program's attributes (aabbs).
__device__ Vec2 hitUv() {
    if (optixIsTriangleHit()) {
        const float2 b = optixGetTriangleBarycentrics();
        return quadUv(optixGetPrimitiveIndex() & 1u, b.x, b.y);
    }
    return Vec2(__uint_as_float(optixGetAttribute_0()), __uint_as_float(optixGetAttribute_1()));
}

/// The alpha test runs in the any-hit for triangles; the intersection
/// program has run it for boxes.
__device__ bool anyHitAlpha() { return params.discAlpha && params.layout != AccelLayout::aabbs; }

/// V(x, p_i) by render.visibility_rule (the CPU's shadowQuery): true when
/// no blocker is found (counted into the thread's counters). Trace:
/// optixTrace (the pipeline path). Else optixTraverse with a hit object (the
/// inline-like path), after optixReorder by the SER key (`hint`, `bits` low
/// bits) when `reorder`.
///
/// With opacity micromaps an opaque micro-triangle accepts a hit without the
/// any-hit, so the identity exclusion cannot run there. The first accepted
/// hit is then reported (closest-hit or hit object), and when it is the
/// receiver's or the light's own billboard (a ray from centre to centre can
/// meet them only at t = 0 and t = D) the ray is traced again past that hit:
/// the exact re-test. It differs from the identity rule only for a blocker
/// within one float step of either end.
template <bool Trace>
__device__ bool visible(const ShadingPoint& sp, std::uint32_t light, const LightTerm& t, LaunchCounters& c,
                        bool reorder = false, unsigned hint = 0, unsigned bits = 0) {
    const ShadowQuery q = params.spheres
                              ? shadowQuery<Primitive::sphere>(params.visibility, sp, light, params.position[light],
                                                               params.radius[light], t)
                              : shadowQuery<Primitive::billboard>(params.visibility, sp, light, params.position[light],
                                                                  params.radius[light], t);
    if (!(q.tfar > q.tnear)) return true;  // an empty interval sees the light (as on the CPU)
    float tnear = q.tnear, tfar = q.tfar;
    const float3 o = make_float3(q.o.x, q.o.y, q.o.z), d = make_float3(q.d.x, q.d.y, q.d.z);
    const unsigned flags = OPTIX_RAY_FLAG_TERMINATE_ON_FIRST_HIT | (params.omm ? 0u : OPTIX_RAY_FLAG_DISABLE_CLOSESTHIT);
    for (int attempt = 0; attempt < 6; ++attempt) {
        unsigned hitId = q.exclude.receiver, lightId = q.exclude.light, occluded = 0, anyHits = 0, tBits = 0;
        bool hit;
        if constexpr (Trace) {
            optixTrace(params.tlas, o, d, tnear, tfar, 0.0f, OptixVisibilityMask(255), flags, kShadowRay, kRayTypes,
                       kShadowRay, hitId, lightId, occluded, anyHits, tBits);
            hit = occluded != 0;
        } else {
            if (reorder && attempt == 0) {
                optixMakeNopHitObject();
                optixReorder(hint, bits);
            }
            optixTraverse(params.tlas, o, d, tnear, tfar, 0.0f, OptixVisibilityMask(255), flags, kShadowRay, kRayTypes,
                          kShadowRay, hitId, lightId, occluded, anyHits, tBits);
            hit = optixHitObjectIsHit();
            if (hit && params.omm) {
                hitId = hitParticle(params, optixHitObjectGetInstanceId(), optixHitObjectGetPrimitiveIndex());
                tBits = __float_as_uint(optixHitObjectGetRayTmax());
            }
        }
        ++c.rays;
        c.anyHits += anyHits;
        if (!hit) return true;
        if (!params.omm || (hitId != q.exclude.receiver && hitId != q.exclude.light)) {
            ++c.occluded;
            return false;
        }
        ++c.retests;  // an excluded billboard's opaque micro-triangle: past it
        const float th = __uint_as_float(tBits);
        if (th < 0.5f * (tnear + tfar)) tnear = nextafterf(th, tfar);
        else tfar = nextafterf(th, tnear);
        if (!(tfar > tnear)) return true;
    }
    return true;
}

__device__ void addCounters(const LaunchCounters& c) {
    if (!params.counters) return;
    if (c.rays) atomicAdd(&params.counters->rays, c.rays);
    if (c.anyHits) atomicAdd(&params.counters->anyHits, c.anyHits);
    if (c.occluded) atomicAdd(&params.counters->occluded, c.occluded);
    if (c.lightTerms) atomicAdd(&params.counters->lightTerms, c.lightTerms);
    if (c.retests) atomicAdd(&params.counters->retests, c.retests);
}

/// light_estimates.h's bridge on the twin: optixTrace shadow rays with
/// any-hit (visibility off: 1, no ray), counted in the launch's counters.
template <ShadingModel M>
struct DeviceLightBridge {
    static constexpr bool traced = false;
    LaunchCounters& c;
    __device__ bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        return twin::lightTerm<M>(params.lights, sp, i, t);
    }
    __device__ void countLightTerm() { ++c.lightTerms; }
    __device__ bool seen(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) {
        return !params.shadows || visible<true>(sp, i, t, c);
    }
};

/// exact: light_estimates.h's sum over every light.
template <ShadingModel M>
__device__ DVec3 exactSum(const ShadingPoint& sp, LaunchCounters& c) {
    DeviceLightBridge<M> b{c};
    return sumLightTerms(b, sp, LightRange{params.particleCount});
}

/// uniform / power (src/render/estimators.cpp, runChunks): per chunk of up
/// to 8 samples a stream of its own (pixel, frame, lightSampling, seed,
/// chunk + 1), the chunk's lights drawn from the source pmf, then shaded by
/// light_estimates.h's shadeLightSamples (f I G V / p(i) added in double),
/// as the CPU does; adaptive sampling (render.target_stderr) stops the pixel
/// at the end of a round.
template <ShadingModel M>
__device__ void samplePixel(const ShadingPoint& sp, std::size_t px, SampleSums& s, LaunchCounters& c) {
    const SamplingParams& sampling = params.sampling;
    const LightingPlan& plan = sampling.plan;
    DeviceLightBridge<M> b{c};
    for (std::uint64_t chunk = plan.begin; chunk < plan.end; ++chunk) {
        PortableRng rng(px, sampling.frame, RngPass::lightSampling, sampling.seed, chunk + 1);
        const std::uint32_t count = plan.chunkSamples(chunk);
        LightSample xs[LightingPlan::kChunkSamples];
        for (std::uint32_t m = 0; m < count; ++m) xs[m] = params.source.sample(rng);
        shadeLightSamples(b, sp, xs, count, DVec3(0.0), s);
        if (plan.adaptive && (chunk + 1) % plan.chunksPerRound == 0 &&
            roundDone(s.sum, s.sumSq, s.n, static_cast<std::uint32_t>((chunk + 1) / plan.chunksPerRound), plan.samples,
                      sampling.maxSamples, sampling.targetStderr))
            return;
    }
}

/// traceShadowRays' shadow ray on the twin: optixTrace with any-hit, or
/// optixTraverse with optionally optixReorder by the SER key (the light's
/// cluster in serHintBits bits).
template <bool Traverse>
struct OptixShadowRays {
    LaunchCounters* c;
    __device__ bool operator()(const ShadingPoint& sp, std::uint32_t light, const LightTerm& t) const {
        const RestirParams& rp = params.restir;
        if constexpr (Traverse) {
            const unsigned mask = rp.serHintBits >= 32 ? 0xffffffffu : (1u << rp.serHintBits) - 1u;
            return visible<false>(sp, light, t, *c, rp.reorder, rp.particleCluster[light] & mask, rp.serHintBits);
        } else {
            return visible<true>(sp, light, t, *c);
        }
    }
};

/// traceShadowRays: restir_passes.h's body over the device bridge, in place
/// on restir.out, with OptiX's shadow rays.
template <ShadingModel SM, bool Traverse>
__device__ void shadePixel() {
    const uint3 idx = optixGetLaunchIndex();
    const std::size_t px = std::size_t(idx.y) * params.restir.reuse.width + idx.x;  // the lighting grid's texel
    LaunchCounters c;
    DeviceBridge<SM, OptixShadowRays<Traverse>> b(params, true, OptixShadowRays<Traverse>{&c}, &c);
    restir::traceShadowRayTexel(b, px);
    addCounters(c);
}

template <bool Traverse>
__device__ void shade() {
    switch (params.model) {
    case ShadingModel::lambert: shadePixel<ShadingModel::lambert, Traverse>(); break;
    case ShadingModel::sphere: shadePixel<ShadingModel::sphere, Traverse>(); break;
    case ShadingModel::isotropic: shadePixel<ShadingModel::isotropic, Traverse>(); break;
    }
}

/// particle_restir's resampleParticlePixels (restir.pixel_shading resample): the pixel resamples its
/// particle's texels (restir.in) at its own point and traces its own shadow ray.
template <ShadingModel SM>
__device__ void resampleParticlePixel() {
    const uint3 idx = optixGetLaunchIndex();
    const std::size_t px = std::size_t(idx.y) * params.camera.width + idx.x;
    LaunchCounters c;
    DeviceBridge<SM, OptixShadowRays<false>> b(params, false, OptixShadowRays<false>{&c}, &c);
    restir::resamplePixel(b, px);
    addCounters(c);
}

}  // namespace

/// The thread of a launch of a thread per ray (twin --ray-launch: one row
/// or rows): idx.y x width + idx.x.
static __forceinline__ __device__ std::size_t rayThread() {
    const uint3 idx = optixGetLaunchIndex(), dim = optixGetLaunchDimensions();
    return std::size_t(idx.y) * dim.x + idx.x;
}

/// voxel_cache's updateVoxelCache, its rays: one thread per ray of each
/// occupied cell (thread c x rays + r: a cell's rays side by side),
/// voxel_cache_passes.h's traceCellRay with OptiX's shadow rays, written for
/// the per-cell sum (voxel_kernels.cu).
extern "C" __global__ void __raygen__updateVoxelCache() {
    const VoxelLaunch& v = params.voxel;
    const std::size_t L = rayThread();
    const std::uint32_t rays = v.params.rays, c = std::uint32_t(L / rays), r = std::uint32_t(L % rays);
    if (!v.occupied[c]) return;
    LaunchCounters counters;
    VoxelBridge<OptixShadowRays<false>> b(params, OptixShadowRays<false>{&counters}, &counters);
    v.rays[std::size_t(c) * rays + r] = voxel::traceCellRay(b, c, r);
    addCounters(counters);
}

/// particle_split's shadeSplitTexels, its rays: one thread per ray of each
/// texel (by default particle_split_passes.h's splitRayThread order: a warp
/// traces one kind of ray, near or far, of a few texels), its traceSplitRay
/// with OptiX's shadow rays, written for the per-texel sum
/// (split_kernels.cu). At 100K, 8 near and 8 far of 8 candidates: 36 ms
/// with a thread per texel, 9.6 with a thread per ray and a warp's rays
/// those of two texels (near and far ones mixed).
template <ShadingModel SM>
__device__ void traceSplitRay() {
    LaunchCounters c;
    SplitBridge<SM, OptixShadowRays<false>> b(params, OptixShadowRays<false>{&c}, &c);
    const SplitLaunch& s = params.split;
    const std::size_t L = rayThread();
    std::size_t q = L % s.rayStride;
    std::uint32_t r = std::uint32_t(L / s.rayStride);
    // twin --ray-launch texels (the default, as the CPU counts it), and far_new's extra rays past every texel's own
    if (s.texelMajor || r >= psplit::raysPerTexel(s.params)) {
        const psplit::SplitRayOfThread t = psplit::splitRayOfThread(s.params, s.rayStride, L, s.newTexels);
        q = t.texel;
        r = t.ray;
    }
    s.rays[std::size_t(r) * s.rayStride + q] = psplit::traceSplitRay(b, q, r);
    addCounters(c);
}

extern "C" __global__ void __raygen__shadeSplitTexels() {
    switch (params.model) {
    case ShadingModel::lambert: traceSplitRay<ShadingModel::lambert>(); break;
    case ShadingModel::sphere: traceSplitRay<ShadingModel::sphere>(); break;
    case ShadingModel::isotropic: traceSplitRay<ShadingModel::isotropic>(); break;
    }
}

extern "C" __global__ void __raygen__resampleParticlePixels() {
    switch (params.model) {
    case ShadingModel::lambert: resampleParticlePixel<ShadingModel::lambert>(); break;
    case ShadingModel::sphere: resampleParticlePixel<ShadingModel::sphere>(); break;
    case ShadingModel::isotropic: resampleParticlePixel<ShadingModel::isotropic>(); break;
    }
}

extern "C" __global__ void __raygen__shade() { shade<false>(); }
extern "C" __global__ void __raygen__shadeTraverse() { shade<true>(); }

extern "C" __global__ void __raygen__gbuffer() {
    const uint3 idx = optixGetLaunchIndex();
    const Camera& cam = params.camera;
    const std::uint32_t x = idx.x, y = idx.y;
    const Vec3 dir = cam.pixelDirection(x, y);
    unsigned inst = 0xffffffffu, prim = 0, b0 = 0, b1 = 0, tb = 0;
    optixTrace(params.tlas, make_float3(cam.position.x, cam.position.y, cam.position.z), make_float3(dir.x, dir.y, dir.z),
               0.0f, __int_as_float(0x7f800000), 0.0f, OptixVisibilityMask(255),
               anyHitAlpha() ? OPTIX_RAY_FLAG_NONE : OPTIX_RAY_FLAG_DISABLE_ANYHIT, kPrimaryRay, kRayTypes, kPrimaryRay,
               inst, prim, b0, b1, tb);
    GBufferTexel g;
    if (inst != 0xffffffffu) {
        const std::uint32_t j = hitParticle(params, inst, prim);
        if (params.spheres) {
            g = sphereTexel(cam, x, y, dir, j, params.position[j], params.radius[j], __uint_as_float(tb));
        } else {
            const Vec2 uv(__uint_as_float(b0), __uint_as_float(b1));
            g = billboardTexel(cam, x, y, dir, j, params.position[j], params.radius[j], params.frames[j], uv, params.model);
        }
    }
    params.gbuffer[std::size_t(y) * cam.width + x] = g;
}

extern "C" __global__ void __raygen__exact() {
    const uint3 idx = optixGetLaunchIndex();
    const std::size_t px = std::size_t(idx.y) * params.camera.width + idx.x;
    const GBufferTexel g = params.gbuffer[px];
    DVec3 sum(0.0);
    LaunchCounters c;
    if (g.hit()) {
        const ShadingPoint sp = shadingPointOf(g, params.lights);
        switch (params.model) {
        case ShadingModel::lambert: sum = exactSum<ShadingModel::lambert>(sp, c); break;
        case ShadingModel::sphere: sum = exactSum<ShadingModel::sphere>(sp, c); break;
        case ShadingModel::isotropic: sum = exactSum<ShadingModel::isotropic>(sp, c); break;
        }
    }
    params.Lr[px] = Vec3(sum);
    addCounters(c);
}

extern "C" __global__ void __raygen__sample() {
    const uint3 idx = optixGetLaunchIndex();
    const std::size_t px = std::size_t(idx.y) * params.camera.width + idx.x;
    const GBufferTexel g = params.gbuffer[px];
    SampleSums s;
    s.discardNonFinite = params.sampling.discardNonFinite;
    LaunchCounters c;
    if (g.hit()) {
        const ShadingPoint sp = shadingPointOf(g, params.lights);
        switch (params.model) {
        case ShadingModel::lambert: samplePixel<ShadingModel::lambert>(sp, px, s, c); break;
        case ShadingModel::sphere: samplePixel<ShadingModel::sphere>(sp, px, s, c); break;
        case ShadingModel::isotropic: samplePixel<ShadingModel::isotropic>(sp, px, s, c); break;
        }
    }
    const bool zeroed = resolveSums(s.sum, s.sumSq, s.n, false, params.Lr[px], params.sampling.Lr_stderr[px], params.sampling.spp[px]);
    params.sampling.rejected[px] = s.rejected + (zeroed ? 1u : 0u);
    addCounters(c);
}

/// The primary hit: instance, primitive, the billboard's quad uv (none for
/// spheres) and t.
extern "C" __global__ void __closesthit__primary() {
    const Vec2 uv = params.spheres ? Vec2(0.0f) : hitUv();
    optixSetPayload_0(optixGetInstanceId());
    optixSetPayload_1(optixGetPrimitiveIndex());
    optixSetPayload_2(__float_as_uint(uv.x));
    optixSetPayload_3(__float_as_uint(uv.y));
    optixSetPayload_4(__float_as_uint(optixGetRayTmax()));
}

extern "C" __global__ void __anyhit__primary() {
    if (!insideDisc(hitUv())) optixIgnoreIntersection();
}

/// The aabbs layout's billboard: the ray meets the plane of particle j's
/// quad (p_j, r_j right, r_j up) inside the quad (and inside the disc under
/// disc alpha); the hit reports its quad uv as two attributes. The frame is
/// the world's (the cluster instances have identity transforms).
extern "C" __global__ void __intersection__billboard() {
    const std::uint32_t j = hitParticle(params, optixGetInstanceId(), optixGetPrimitiveIndex());
    const float3 o = optixGetWorldRayOrigin(), d = optixGetWorldRayDirection();
    float t;
    Vec2 uv;
    if (intersectBillboard(Vec3(o.x, o.y, o.z), Vec3(d.x, d.y, d.z), optixGetRayTmin(), optixGetRayTmax(),
                           params.position[j], params.radius[j], params.frames[j], params.discAlpha, t, uv))
        optixReportIntersection(t, 0, __float_as_uint(uv.x), __float_as_uint(uv.y));
}

/// A shadow ray's first accepted hit (opacity micromaps only: otherwise
/// closest-hit is disabled): its particle and t, for the exact re-test.
extern "C" __global__ void __closesthit__shadow() {
    optixSetPayload_0(hitParticle(params, optixGetInstanceId(), optixGetPrimitiveIndex()));
    optixSetPayload_2(1);
    optixSetPayload_4(__float_as_uint(optixGetRayTmax()));
}

extern "C" __global__ void __anyhit__shadow() {
    optixSetPayload_3(optixGetPayload_3() + 1);
    const std::uint32_t j = hitParticle(params, optixGetInstanceId(), optixGetPrimitiveIndex());
    if (j == optixGetPayload_0() || j == optixGetPayload_1()) optixIgnoreIntersection();
    if (anyHitAlpha() && !insideDisc(hitUv())) optixIgnoreIntersection();
    optixSetPayload_2(1);
    optixTerminateRay();
}

extern "C" __global__ void __miss__none() {}
