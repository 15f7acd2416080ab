// temporalResampling: reuse of last frame's reservoir at the reprojected
// point, the body of restir_passes.h over the CPU's bridge.
#include "cpu_bridge.h"

namespace accretion::restir {

/// Reprojection through particle motion and the previous camera; rejection
/// on particle, normal and depth; history M capped at m_cap x M.
LightingCounters temporalResampling(const FrameContext& f, const std::vector<StoredReservoir>& cur, std::vector<StoredReservoir>& out) {
    ACC_CHECK(f.prev && f.prev->gbuffer.width == f.lg.width && f.prev->gbuffer.height == f.lg.height);
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::temporalResampling, CpuBuffers{&cur, &out},
                                          [](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { temporalResamplingTexel(b, px); });
    });
}

}  // namespace accretion::restir
