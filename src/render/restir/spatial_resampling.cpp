// spatialResampling: reuse of k neighbours' reservoirs in a disc of texels,
// the body of restir_passes.h over the CPU's bridge.
#include "cpu_bridge.h"

namespace accretion::restir {

/// k neighbours uniform in a disc of spatial_radius (scaled to the lighting
/// grid); iteration seeds the pass's streams.
LightingCounters spatialResampling(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                   std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::spatialResampling, CpuBuffers{&cur, &out},
                                          [&](auto& b, std::size_t px, std::uint32_t x, std::uint32_t y) {
                                              spatialResamplingTexel(b, px, x, y, iteration);
                                          });
    });
}

}  // namespace accretion::restir
