#pragma once
#include <cstdint>

namespace accretion {

/// A light drawn by a light sampler, with its probability.
struct LightSample {
    std::uint32_t i;  ///< light index, kNoLightSample when every light has zero importance
    float pdf;        ///< probability of i (0 with kNoLightSample)
};

inline constexpr std::uint32_t kNoLightSample = 0xffffffffu;

}  // namespace accretion
