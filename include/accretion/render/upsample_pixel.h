#pragma once
// upsampleLighting's per-pixel rule, shared by the CPU pass and the OptiX
// twin (ACC_HD): both grids row-major, the lighting grid at `scale` of the image.
#include <cmath>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/lighting/resampling.h"
#include "accretion/render/gbuffer_texel.h"

namespace accretion {

/// The lighting grid's width (height) for an image width (height) at `scale`.
inline std::uint32_t lightingGridExtent(std::uint32_t full, float scale) {
    const auto n = static_cast<std::uint32_t>(std::lround(float(full) * scale));
    return n > 1u ? n : 1u;
}

/// The lighting-grid texel of reduced texel (x, y): the image pixel that
/// contains its centre.
ACC_HD inline void reducedTexelSource(std::uint32_t x, std::uint32_t y, float scale, std::uint32_t width, std::uint32_t height,
                                      std::uint32_t& fx, std::uint32_t& fy) {
    const auto sx = std::uint32_t((float(x) + 0.5f) / scale), sy = std::uint32_t((float(y) + 0.5f) / scale);
    fx = sx < width - 1 ? sx : width - 1;
    fy = sy < height - 1 ? sy : height - 1;
}

/// Bilateral upsample of Lr / rho at image pixel (x, y) with texel g:
/// bilinear weights of the four nearest lighting texels (at least 1e-4)
/// times depth and normal similarity, then times the pixel's own albedo.
ACC_HD inline Vec3 upsamplePixel(const GBufferTexel& g, std::uint32_t x, std::uint32_t y, float scale, const GBufferTexel* lg,
                                 std::uint32_t lw, std::uint32_t lh, const Vec3* lowLr, const Vec3* albedo,
                                 float normalThreshold, float depthThreshold) {
    if (!g.hit()) return Vec3(0.0f);
    const float fx = (float(x) + 0.5f) * scale - 0.5f, fy = (float(y) + 0.5f) * scale - 0.5f;
    const int x0 = int(floorf(fx)), y0 = int(floorf(fy));
    Vec3 sum(0.0f);
    float wsum = 0.0f;
    for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
            int lx = x0 + dx, ly = y0 + dy;
            lx = lx < 0 ? 0 : (lx > int(lw) - 1 ? int(lw) - 1 : lx);
            ly = ly < 0 ? 0 : (ly > int(lh) - 1 ? int(lh) - 1 : ly);
            const float bw = (dx ? fx - float(x0) : 1.0f - (fx - float(x0))) * (dy ? fy - float(y0) : 1.0f - (fy - float(y0)));
            const std::size_t q = std::size_t(ly) * lw + std::size_t(lx);
            const GBufferTexel& gl = lg[q];
            if (!gl.hit() || !resampling::similarSurface(g.normal, g.depth, gl.normal, gl.depth, normalThreshold, depthThreshold))
                continue;
            const Vec3 e = glm::max(albedo[gl.particle], Vec3(1e-8f));
            const float w = bw > 1e-4f ? bw : 1e-4f;
            sum += w * lowLr[q] / e;
            wsum += w;
        }
    }
    return wsum > 0.0f ? sum / wsum * albedo[g.particle] : Vec3(0.0f);
}

}  // namespace accretion
