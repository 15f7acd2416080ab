// traceShadowRays: one shadow ray for the kept sample, and Lr.
#include "restir_pass.h"
#include "accretion/render/restir_steps.h"

namespace accretion::restir {
namespace {

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters traceShadowRaysKernel(const FrameContext& f, std::vector<StoredReservoir>& res, std::vector<Vec3>& Lr) {
    PassCounters* pc = passCounters<Count>(f, Pass::traceShadowRays);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c) {
        Lr[px] = Vec3(0.0f);
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        rec.write(gpu_layout::kRadiance);
        StoredReservoir& r = res[px];
        if (!g.hit()) return;
        rec.read(R);
        if (!(r.W > 0.0f)) return;
        rec.read(gpu_layout::kParticleRecord);
        rec.gather(1);
        if constexpr (Count) rec.hint(f.in.bvh.clusterOf(r.y));
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        LightTerm t;
        ++c.lightTerms;
        if (!f.L.term<SM>(sp, r.y, t)) return;
        bool seen = true;
        if (f.shadows) {
            ++c.shadowRays;
            rec.trip();
            RayCounters rc;
            seen = visible<P>(f.in.bvh, f.vis, sp, r.y, f.L.packed[r.y].position, f.L.packed[r.y].radius, t, rec.rayCounters(rc));
            rec.ray(rc);
        }
        switch (shadeSample(t, r.W, seen, Lr[px])) {
        case Shade::lit: break;
        case Shade::occluded:
            ++c.shadowOccluded;
            if (f.rs.visibility_reuse) {
                r = f.codec.roundTrip(occludedReservoir(r));
                rec.write(R);
            }
            break;
        case Shade::overflow:  // a zero sample (discard: and no reservoir for reuse)
            if (f.reject(px, c)) r = f.codec.roundTrip(StoredReservoir{});
            break;
        }
    });
}

}  // namespace

/// One shadow ray for the kept sample; Lr = f I G V W. With visibility
/// reuse, an occluded sample's W is zeroed in the stored reservoir.
LightingCounters traceShadowRays(const FrameContext& f, std::vector<StoredReservoir>& res, std::vector<Vec3>& Lr) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() { return traceShadowRaysKernel<SM, P, Count>(f, res, Lr); });
}

}  // namespace accretion::restir
