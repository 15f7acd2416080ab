#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// How a preview maps radiance to 8-bit sRGB: each channel times `scale`,
/// then the curve. Auto exposure takes the scale from the image's lit
/// (non-black) pixels: filmic puts their median luminance at 0.18 (middle
/// grey) and lets the ACES fit roll off the bright centre; log divides by
/// the median and maps log2(1 + x) so that the 99.9th percentile is white;
/// linear puts the 99.5th percentile at 1 and clips.
struct PreviewTone {
    ToneMap curve = ToneMap::filmic;
    double scale = 1.0;      ///< radiance multiplier, user exposure included
    double white = 1.0;      ///< log: the scaled value shown white
    double exposure = 0.0;   ///< user stops (render.exposure)
    double anchor = 0.0;     ///< the luminance auto exposure used (0: none)
    bool autoExposure = true;

    /// One line for the EXR metadata (accretion:preview) and the stats.
    std::string describe() const;
    /// The 8-bit sRGB value of a radiance channel.
    std::uint8_t encode(float radiance) const;
};

PreviewTone previewTone(const std::vector<Vec3>& rgb, ToneMap curve, bool autoExposure, double exposure);

/// An 8-bit sRGB PNG of an RGB buffer through `tone`. Atomic.
void writePreviewPng(const std::filesystem::path& file, const std::vector<Vec3>& rgb, std::uint32_t width,
                     std::uint32_t height, const PreviewTone& tone);

}  // namespace accretion
