// upsampleLighting: Lr from the reduced lighting grid to every image pixel.
#include "restir_pass.h"

#include "accretion/lighting/resampling.h"

namespace accretion::restir {

/// Bilateral upsample of Lr / rho from the lighting grid: bilinear weights
/// times depth and normal similarity, then times the pixel's own albedo.
void upsampleLighting(const GBuffer& full, const GBuffer& lg, const Particles& particles, const std::vector<Vec3>& lowLr,
                      float scale, const RestirSettings& rs, std::vector<Vec3>& Lr) {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, full.height), [&](const auto& rows) {
        for (std::uint32_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::uint32_t x = 0; x < full.width; ++x) {
                const std::size_t px = std::size_t(y) * full.width + x;
                const GBufferTexel& g = full.texels[px];
                Lr[px] = Vec3(0.0f);
                if (!g.hit()) continue;
                const float fx = (float(x) + 0.5f) * scale - 0.5f, fy = (float(y) + 0.5f) * scale - 0.5f;
                const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
                Vec3 sum(0.0f);
                float wsum = 0.0f;
                for (int dy = 0; dy < 2; ++dy) {
                    for (int dx = 0; dx < 2; ++dx) {
                        const int lx = std::clamp(x0 + dx, 0, int(lg.width) - 1);
                        const int ly = std::clamp(y0 + dy, 0, int(lg.height) - 1);
                        const float bw = (dx ? fx - float(x0) : 1.0f - (fx - float(x0))) *
                                         (dy ? fy - float(y0) : 1.0f - (fy - float(y0)));
                        const std::size_t q = std::size_t(ly) * lg.width + std::size_t(lx);
                        const GBufferTexel& gl = lg.texels[q];
                        if (!gl.hit() || !resampling::similarSurface(g.normal, g.depth, gl.normal, gl.depth,
                                                                     float(rs.normal_threshold), float(rs.depth_threshold)))
                            continue;
                        const Vec3 rho = particles.albedo[gl.particle];
                        const Vec3 e = glm::max(rho, Vec3(1e-8f));
                        const float w = std::max(bw, 1e-4f);
                        sum += w * lowLr[q] / e;
                        wsum += w;
                    }
                }
                if (wsum > 0.0f) Lr[px] = sum / wsum * particles.albedo[g.particle];
            }
        }
    });
}

void recordUpsample(const RestirInputs& in, PassCounters& pc) {
    // Per image pixel: its texel, then four lighting texels (G-buffer + radiance) as loop trips.
    const GBuffer& full = in.gbuffer;
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
