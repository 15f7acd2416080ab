#pragma once
// render --pixel: one pixel of one frame, explained.
#include <cstdint>

#include "accretion/scene/settings.h"

namespace accretion::cmd {

/// Renders the frames of the settings (restir: all of them, for its history;
/// the others: each frame's crop of one pixel) and prints, for pixel (x, y)
/// of the last frame, the hit, the estimator's terms, samples or reservoirs,
/// and the pixel's values (shortest round-trip decimals: bit for bit those of
/// the full render). Writes no file.
void explainPixel(const Settings& settings, std::uint32_t x, std::uint32_t y, bool quiet);

}  // namespace accretion::cmd
