// traceShadowRays: one shadow ray for the kept sample, and Lr; the body of
// restir_passes.h over the CPU's bridge.
#include "cpu_bridge.h"

namespace accretion::restir {

/// One shadow ray for the kept sample; Lr = f I G V W. With visibility
/// reuse, an occluded sample's W is zeroed in the stored reservoir.
LightingCounters traceShadowRays(const FrameContext& f, std::vector<StoredReservoir>& res, std::vector<Vec3>& Lr) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::traceShadowRays, CpuBuffers{&res, &res, &Lr},
                                          [](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { traceShadowRayTexel(b, px); });
    });
}

}  // namespace accretion::restir
