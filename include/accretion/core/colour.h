#pragma once
// Display transforms shared by the previews and FLIP.

namespace accretion {

/// Linear <-> sRGB transfer (IEC 61966-2-1), for values in [0, 1].
float linearToSrgb(float v);
float srgbToLinear(float v);

/// The ACES filmic fit (Narkowicz 2016) of a linear value, its 0.6
/// pre-exposure included, clamped to [0, 1]; +inf maps to 1, negative to 0.
float acesToneMap(float x);

}  // namespace accretion
