#pragma once
// The G-buffer texel's layout, below every layer that reads or prices it
// (counters/gpu_layouts.h charges its size); render/gbuffer_texel.h builds
// texels from primary hits.
#include <cstdint>

#include "accretion/core/math.h"

namespace accretion {

inline constexpr std::uint32_t kNoParticle = 0xffffffffu;

/// One G-buffer texel: what the primary ray through the pixel centre hit
/// (44 bytes: the lighting passes stream it for every pixel). The hit point
/// is not stored: shadingPoint() forms x = p_j + local.
struct GBufferTexel {
    std::uint32_t particle = kNoParticle; ///< hit particle, kNoParticle on a miss
    Vec3 local{0.0f};                     ///< x - p_j, from the pixel ray intersected in double
    Vec3 normal{0.0f};                    ///< shading normal n
    Vec3 geomNormal{0.0f};                ///< geometric normal (origin offsets)
    float depth = 0.0f;                   ///< camera-space z (along the view direction)
    ACC_HD bool hit() const { return particle != kNoParticle; }
};

static_assert(sizeof(GBufferTexel) == 44, "the texel the lighting passes stream");

}  // namespace accretion
