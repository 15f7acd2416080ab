// Preview tone curves: the exposure comes from the image as stated.
#include <catch2/catch.hpp>

#include <cmath>

#include "accretion/io/preview.h"

using namespace accretion;

namespace {
std::uint8_t srgb8(double linear) {
    const double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
    return std::uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}
double aces(double x) { x *= 0.6; return std::clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); }
}  // namespace

TEST_CASE("preview tone: filmic puts the median lit pixel at middle grey, black stays black", "[preview]") {
    // 60% black sky; grey lit pixels 1 .. 40 (luminance = value).
    std::vector<Vec3> img(60, Vec3(0.0f));
    for (int k = 1; k <= 40; ++k) img.push_back(Vec3(float(k)));
    const PreviewTone t = previewTone(img, ToneMap::filmic, true, 0.0);
    CHECK(t.anchor == Approx(21.0));  // the lit median (index 20 of 40)
    CHECK(t.scale == Approx(0.18 / 21.0));
    CHECK(t.encode(21.0f) == srgb8(aces(0.18)));
    CHECK(t.encode(0.0f) == 0);
    CHECK(t.encode(1e30f) == 255);
    CHECK(t.describe().find("median lit luminance 21 -> 0.18") != std::string::npos);
    // One stop of exposure doubles the scale.
    CHECK(previewTone(img, ToneMap::filmic, true, 1.0).scale == Approx(2.0 * t.scale));
    // log: the 99.9th percentile is white, the median at log2(2) / log2(1 + white).
    const PreviewTone l = previewTone(img, ToneMap::log, true, 0.0);
    CHECK(l.encode(40.0f) == 255);
    CHECK(l.encode(21.0f) == srgb8(1.0 / std::log2(1.0 + 40.0 / 21.0)));
    // linear: the 99.5th percentile at 1, clipped above.
    const PreviewTone lin = previewTone(img, ToneMap::linear, true, 0.0);
    CHECK(lin.encode(40.0f) == 255);
    CHECK(lin.encode(20.0f) == srgb8(0.5));
}
