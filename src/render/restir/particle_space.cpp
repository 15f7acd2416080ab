// particle_restir's own passes on the CPU: the bodies of
// particle_restir_passes.h over the CPU's bridge. generateCandidates and
// traceShadowRays run on the texels as restir's do.
#include "accretion/render/particle_restir_passes.h"
#include "cpu_bridge.h"

namespace accretion::restir {

/// Temporal reuse by particle id: last frame's reservoir of the same texel.
LightingCounters temporalResamplingById(const FrameContext& f, const std::vector<StoredReservoir>& cur,
                                        std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::temporalResampling, CpuBuffers{&cur, &out},
                                          [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { temporalByIdTexel(b, px); });
    });
}

/// Spatial reuse among the texels of the world neighbours (Morton order).
LightingCounters resampleWorldNeighbours(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                        std::vector<StoredReservoir>& out) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::resampleWorldNeighbours, CpuBuffers{&cur, &out},
                                          [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) {
                                              spatialWorldTexel(b, px, iteration);
                                          });
    });
}

LightingCounters accumulateTexelLr(const FrameContext& f, std::vector<Vec3>& texelLr) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        // Counted with traceShadowRays, whose kernel it ends on the GPU.
        return forEachTexel<SM, P, false>(f, Pass::traceShadowRays, CpuBuffers{nullptr, nullptr, &texelLr, &texelLr},
                                          [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { accumulateTexelLr(b, px); });
    });
}

LightingCounters shadeParticlePixels(const FrameContext& f, const std::vector<Vec3>& texelLr, std::vector<Vec3>& Lr) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::shadeParticlePixels, CpuBuffers{nullptr, nullptr, &Lr, &texelLr},
                                          [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { interpolatePixel(b, px); });
    });
}

LightingCounters resampleParticlePixels(const FrameContext& f, const std::vector<StoredReservoir>& texelReservoirs,
                                        std::vector<Vec3>& Lr) {
    return dispatchKernel(f, [&]<ShadingModel SM, Primitive P, bool Count>() {
        return forEachTexel<SM, P, Count>(f, Pass::resampleParticlePixels, CpuBuffers{&texelReservoirs, nullptr, &Lr, nullptr},
                                          [&](auto& b, std::size_t px, std::uint32_t, std::uint32_t) { resamplePixel(b, px); });
    });
}

}  // namespace accretion::restir
