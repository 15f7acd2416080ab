#pragma once
// composeImage's loop (docs/MODEL.md section 3), one definition for the CPU
// frame renderer and the OptiX twin's host: over a G-buffer's texels, L =
// Le + Lr on a hit (composeHit), the background on a miss, and the depth,
// normal and particle layers.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// The layers composeLayers writes (sized to the texels), and the lighting
/// layers it reads and amends. Lr_stderr, spp and rejected may be empty (the
/// twin's exact and restir frames have none).
struct ComposeLayers {
    std::vector<Vec3>& L;
    std::vector<Vec3>& Le;
    std::vector<float>& depth;
    std::vector<Vec3>& normal;
    std::vector<std::uint32_t>& particle;
    std::vector<Vec3>& Lr;              ///< 0 on a miss; zeroed with Le and L where L overflows
    std::vector<Vec3>& Lr_stderr;       ///< zeroed where L overflows
    std::vector<float>& rejected;       ///< + 1 where L overflows
    const std::vector<float>& spp;      ///< read for the statistics
};

/// What composeLayers counted.
struct ComposeTotals {
    std::size_t hits = 0;
    std::size_t nonFinite = 0;  ///< hit pixels whose L overflowed (composeImage's rejections)
    double sppSum = 0.0, maxSpp = 0.0;
};

ComposeTotals composeLayers(const std::vector<GBufferTexel>& texels, const std::vector<Vec3>& emission,
                            const ShadingSettings& shading, ComposeLayers out);

}  // namespace accretion
