#include "accretion/render/compose_image.h"

#include <algorithm>
#include <limits>

#include "accretion/render/compose_pixel.h"

namespace accretion {

ComposeTotals composeLayers(const std::vector<GBufferTexel>& texels, const std::vector<Vec3>& emission,
                            const ShadingSettings& shading, ComposeLayers out) {
    const std::size_t pixels = texels.size();
    out.L.resize(pixels);
    out.Le.assign(pixels, Vec3(0.0f));
    out.depth.resize(pixels);
    out.normal.assign(pixels, Vec3(0.0f));
    out.particle.resize(pixels);
    const bool sampled = !out.Lr_stderr.empty();
    const float se = static_cast<float>(shading.self_emission);
    ComposeTotals totals;
    for (std::size_t px = 0; px < pixels; ++px) {
        const GBufferTexel& g = texels[px];
        out.particle[px] = g.particle;
        if (!g.hit()) {
            out.L[px] = shading.background;
            out.depth[px] = std::numeric_limits<float>::infinity();
            out.Lr[px] = Vec3(0.0f);
            continue;
        }
        ++totals.hits;
        if (!composeHit(se, emission[g.particle], out.Lr[px], out.Le[px], out.L[px])) {
            ++totals.nonFinite;
            if (sampled) out.Lr_stderr[px] = Vec3(0.0f);
            if (!out.rejected.empty()) out.rejected[px] += 1.0f;
        }
        out.depth[px] = g.depth;
        out.normal[px] = g.normal;
        if (!out.spp.empty()) {
            totals.sppSum += out.spp[px];
            totals.maxSpp = std::max(totals.maxSpp, double(out.spp[px]));
        }
    }
    return totals;
}

}  // namespace accretion
