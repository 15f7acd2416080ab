#include "accretion/core/colour.h"

#include <algorithm>
#include <cmath>

namespace accretion {

float linearToSrgb(float v) { return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f; }
float srgbToLinear(float v) { return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f); }

float acesToneMap(float x) {
    const double v = x > 0.0f ? double(x) : 0.0;  // NaN and negatives: 0
    if (!std::isfinite(v)) return 1.0f;
    constexpr double k0 = 0.6 * 0.6 * 2.51, k1 = 0.6 * 0.03, k3 = 0.6 * 0.6 * 2.43, k4 = 0.6 * 0.59, k5 = 0.14;
    return float(std::clamp((k0 * v * v + k1 * v) / (k3 * v * v + k4 * v + k5), 0.0, 1.0));
}

}  // namespace accretion
