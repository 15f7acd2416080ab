#include "accretion/io/false_colour.h"

#include <algorithm>
#include <cmath>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"

namespace accretion {
namespace {

constexpr const char* kFont = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// The colour of t in [0, 1] on the scale's ramp (linear interpolation of stops, sRGB).
void colourOf(double t, bool diverging, float rgb[3]) {
    static const float div[3][3] = {{0.23f, 0.30f, 0.75f}, {0.97f, 0.97f, 0.97f}, {0.71f, 0.02f, 0.15f}};
    static const float seq[5][3] = {{0.27f, 0.00f, 0.33f}, {0.23f, 0.32f, 0.55f}, {0.13f, 0.57f, 0.55f},
                                    {0.37f, 0.79f, 0.38f}, {0.99f, 0.91f, 0.14f}};
    const int stops = diverging ? 3 : 5;
    const double x = std::clamp(t, 0.0, 1.0) * (stops - 1);
    const int a = std::min(stops - 2, int(x));
    const float f = float(x - a);
    for (int c = 0; c < 3; ++c) {
        const float lo = diverging ? div[a][c] : seq[a][c], hi = diverging ? div[a + 1][c] : seq[a + 1][c];
        rgb[c] = lo + f * (hi - lo);
    }
}

std::string label(double v) { return v == 0.0 ? std::string("0") : std::fabs(v) >= 1e-3 && std::fabs(v) < 1e4 ? fmt::format("{:.4g}", v) : fmt::format("{:.2e}", v); }

}  // namespace

double symmetricScale(const std::vector<float>& values) {
    std::vector<float> a;
    a.reserve(values.size());
    for (float v : values)
        if (std::isfinite(v)) a.push_back(std::fabs(v));
    if (a.empty()) return 1.0;
    const std::size_t k = std::min(a.size() - 1, std::size_t(0.99 * double(a.size())));
    std::nth_element(a.begin(), a.begin() + std::ptrdiff_t(k), a.end());
    return a[k] > 0.0f ? double(a[k]) : 1.0;
}

void writeFalseColourPng(const std::filesystem::path& file, const std::vector<float>& values, std::uint32_t width,
                         std::uint32_t height, const ColourScale& scale) {
    ACC_CHECK(values.size() == std::size_t(width) * height);
    const int W = std::max<int>(int(width), 520), barTop = int(height) + 6, barH = 14, H = int(height) + 74;
    OIIO::ImageBuf img(OIIO::ImageSpec(W, H, 3, OIIO::TypeDesc::FLOAT));
    OIIO::ImageBufAlgo::zero(img);
    const double span = scale.hi - scale.lo;
    float rgb[3];
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const float v = values[std::size_t(y) * width + x];
            if (std::isfinite(v)) colourOf(span > 0 ? (v - scale.lo) / span : 0.5, scale.diverging, rgb);
            else rgb[0] = rgb[1] = rgb[2] = 0.5f;
            img.setpixel(int(x), int(y), rgb);
        }
    // The colour bar, from lo (left) to hi (right), under the image.
    const int barX0 = 10, barX1 = W - 10;
    for (int x = barX0; x < barX1; ++x) {
        colourOf(double(x - barX0) / double(barX1 - barX0 - 1), scale.diverging, rgb);
        for (int y = barTop; y < barTop + barH; ++y) img.setpixel(x, y, rgb);
    }
    if (std::filesystem::exists(kFont)) {
        const float white[3] = {1.0f, 1.0f, 1.0f};
        const int textY = barTop + barH + 14, size = 13;
        OIIO::ImageBufAlgo::render_text(img, barX0, textY, label(scale.lo), size, kFont, white);
        if (scale.diverging)
            OIIO::ImageBufAlgo::render_text(img, (barX0 + barX1) / 2, textY, "0", size, kFont, white,
                                            OIIO::ImageBufAlgo::TextAlignX::Center);
        OIIO::ImageBufAlgo::render_text(img, barX1, textY, label(scale.hi), size, kFont, white,
                                        OIIO::ImageBufAlgo::TextAlignX::Right);
        // The title on two lines when it has a parenthesis: each must fit the panel (at least 520 pixels).
        const auto paren = scale.title.find(" (");
        OIIO::ImageBufAlgo::render_text(img, barX0, textY + 17, scale.title.substr(0, paren), size, kFont, white);
        if (paren != std::string::npos)
            OIIO::ImageBufAlgo::render_text(img, barX0, textY + 34, scale.title.substr(paren + 1), size, kFont, white);
    }
    img.specmod().attribute("ImageDescription", fmt::format("{}: scale [{}, {}]", scale.title, scale.lo, scale.hi));
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        if (!img.write(tmp.string(), OIIO::TypeDesc::UINT8))
            throw InputError(fmt::format("{}: cannot write PNG: {}", file.string(), img.geterror()));
    });
}

}  // namespace accretion
