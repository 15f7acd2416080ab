#pragma once
#include <cstdint>

#include "accretion/core/math.h"

namespace accretion {

/// The receiver of one pixel: the G-buffer texel the shading equation needs.
/// Positions are relative to the frame's origin (the camera); the hit point
/// is also kept relative to its particle, so that distances to the lights
/// lose no precision to the magnitude of the coordinates.
struct ShadingPoint {
    Vec3 x;               ///< hit position (shadow ray origin)
    Vec3 n;               ///< shading normal (faces the camera)
    Vec3 ng;              ///< geometric normal, for the ray origin offset
    Vec3 rho;             ///< albedo of the hit particle
    std::uint32_t self;   ///< hit particle j (excluded from its own lighting)
    Vec3 centre;          ///< p_j
    Vec3 local;           ///< x - p_j, computed in double
};

}  // namespace accretion
