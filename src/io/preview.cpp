#include "accretion/io/preview.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "accretion/core/colour.h"
#include "accretion/io/exr_output.h"

namespace accretion {
namespace {

/// The q-quantile (0..1) of the lit pixels' luminance (0 when none is lit).
double litQuantile(const std::vector<Vec3>& rgb, double q) {
    std::vector<float> lum;
    lum.reserve(rgb.size());
    for (const Vec3& c : rgb)
        if (const float y = luminance(c); y > 0.0f && std::isfinite(y)) lum.push_back(y);
    if (lum.empty()) return 0.0;
    const std::size_t k = std::min(lum.size() - 1, std::size_t(q * double(lum.size())));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    return lum[k];
}

}  // namespace

PreviewTone previewTone(const std::vector<Vec3>& rgb, ToneMap curve, bool autoExposure, double exposure) {
    PreviewTone t;
    t.curve = curve;
    t.exposure = exposure;
    t.autoExposure = autoExposure;
    t.scale = std::exp2(exposure);
    if (autoExposure) {
        t.anchor = litQuantile(rgb, curve == ToneMap::linear ? 0.995 : 0.5);
        if (t.anchor > 0.0) t.scale *= (curve == ToneMap::filmic ? 0.18 : 1.0) / t.anchor;
    }
    if (curve == ToneMap::log) {
        const double p999 = litQuantile(rgb, 0.999) * t.scale;
        t.white = p999 > 0.0 ? p999 : 1.0;
    }
    return t;
}

std::uint8_t PreviewTone::encode(float radiance) const {
    const float x = float(scale * double(radiance));
    float v;
    switch (curve) {
    case ToneMap::filmic: v = acesToneMap(x); break;
    case ToneMap::log: v = x > 0.0f ? float(std::log2(1.0 + double(x)) / std::log2(1.0 + white)) : 0.0f; break;
    default: v = x; break;
    }
    v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : (v > 0 ? 1.0f : 0.0f);
    return static_cast<std::uint8_t>(std::lround(linearToSrgb(v) * 255.0f));
}

std::string PreviewTone::describe() const {
    const std::string how = !autoExposure || anchor <= 0.0 ? std::string("fixed exposure")
                            : curve == ToneMap::filmic ? fmt::format("median lit luminance {:.6g} -> 0.18", anchor)
                            : curve == ToneMap::log    ? fmt::format("median lit luminance {:.6g} -> 1", anchor)
                                                       : fmt::format("99.5th percentile luminance {:.6g} -> 1", anchor);
    const std::string curveName = curve == ToneMap::filmic ? "filmic (ACES fit, Narkowicz 2016)"
                                  : curve == ToneMap::log  ? fmt::format("log2(1 + x) / log2(1 + {:.6g})", white)
                                                           : "linear, clipped";
    return fmt::format("{}; radiance x {:.6g} ({}, {:+g} stops); sRGB 8-bit", curveName, scale, how, exposure);
}

void writePreviewPng(const std::filesystem::path& file, const std::vector<Vec3>& rgb, std::uint32_t width,
                     std::uint32_t height, const PreviewTone& tone) {
    std::vector<std::uint8_t> px(rgb.size() * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i)
        for (int c = 0; c < 3; ++c) px[3 * i + c] = tone.encode(rgb[i][c]);
    writeRgb8Png(file, px, width, height);
}

}  // namespace accretion
