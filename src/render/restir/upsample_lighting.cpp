// upsampleLighting: Lr from the reduced lighting grid to every image pixel.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "restir_pass.h"

#include "accretion/render/upsample_pixel.h"

namespace accretion::restir {

/// Bilateral upsample of Lr / rho from the lighting grid (upsamplePixel).
void upsampleLighting(const GBuffer& full, const GBuffer& lg, const Particles& particles, const std::vector<Vec3>& lowLr,
                      float scale, const RestirSettings& rs, std::vector<Vec3>& Lr) {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, full.height), [&](const auto& rows) {
        for (std::uint32_t y = rows.begin(); y != rows.end(); ++y)
            for (std::uint32_t x = 0; x < full.width; ++x) {
                const std::size_t px = std::size_t(y) * full.width + x;
                Lr[px] = upsamplePixel(full.texels[px], x, y, scale, lg.texels.data(), lg.width, lg.height, lowLr.data(),
                                       particles.albedo.data(), float(rs.normal_threshold), float(rs.depth_threshold));
            }
    });
}

void recordUpsample(const RestirInputs& in, const GBuffer& lightingGrid, PassCounters& pc) {
    // Per image pixel: its texel, then four lighting texels (G-buffer + radiance) as loop trips.
    const GBuffer& full = in.gbuffer;
    pc.footprintBytes = std::uint64_t(lightingGrid.width) * lightingGrid.height * (gpu_layout::kGBufferTexel + gpu_layout::kRadiance);
    for (std::size_t px = 0; px < full.texels.size(); ++px) {
        const GBufferTexel& g = full.texels[px];
        ThreadCounters& t = pc.threads[px];
        recordTexel(t, g, in.particles, in.bvh, gpu_layout::kGBufferTexel);
        t.bytesWritten = gpu_layout::kRadiance;
        if (!g.hit()) continue;
        t.trips = 4;
        t.bytesRead += 4 * (gpu_layout::kGBufferTexel + gpu_layout::kRadiance);
    }
}

}  // namespace accretion::restir
