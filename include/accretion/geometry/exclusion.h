#pragma once
#include <cstdint>

namespace accretion {

inline constexpr std::uint32_t kNotExcluded = 0xffffffffu;

/// The primitives an occlusion query ignores by identity (docs/MODEL.md section
/// 3): the receiver j and the light i of V(x, p_i), whatever the geometry
/// of either crosses; no epsilon is involved.
struct Exclusion {
    std::uint32_t receiver = kNotExcluded;
    std::uint32_t light = kNotExcluded;
};

}  // namespace accretion
