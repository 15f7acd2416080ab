#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace accretion {

/// How a scalar image maps to colour: [lo, hi] onto the ramp (diverging:
/// blue, white at 0, red, for signed values; else a dark-to-yellow ramp),
/// with a title and unit printed under the colour bar.
struct ColourScale {
    double lo = 0.0, hi = 1.0;
    bool diverging = false;
    std::string title;  ///< e.g. "relative error (x - ref) / (|ref| + 0.01)"
};

/// A symmetric scale for signed values: +-the 99th percentile of |v| (finite
/// values; 1 when all are 0).
double symmetricScale(const std::vector<float>& values);

/// Write `values` (width x height, row-major; non-finite drawn grey) as an
/// 8-bit PNG in false colour, with a colour bar under the image labelled
/// with the scale's ends and title (DejaVu Sans from fonts-dejavu-core;
/// without the font the bar is drawn unlabelled). Atomic.
void writeFalseColourPng(const std::filesystem::path& file, const std::vector<float>& values, std::uint32_t width,
                         std::uint32_t height, const ColourScale& scale);

}  // namespace accretion
