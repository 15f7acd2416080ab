#include "accretion/io/false_colour.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <ft2build.h>
#include FT_FREETYPE_H
#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/io/png_file.h"

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

/// An RGB float canvas the labels are drawn on, then stored as 8-bit sRGB.
struct Canvas {
    int width, height;
    std::vector<float> rgb;

    Canvas(int w, int h) : width(w), height(h), rgb(std::size_t(w) * std::size_t(h) * 3, 0.0f) {}
    /// Pixel (x, y)'s three floats, or null outside the canvas.
    float* at(int x, int y) {
        if (x < 0 || y < 0 || x >= width || y >= height) return nullptr;
        return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3];
    }
    void set(int x, int y, const float c[3]) {
        if (float* p = at(x, y)) std::copy(c, c + 3, p);
    }
    /// White text covering a pixel by `alpha` (0..1).
    void blendWhite(int x, int y, float alpha) {
        if (float* p = at(x, y))
            for (int k = 0; k < 3; ++k) p[k] = p[k] * (1.0f - alpha) + alpha;
    }
    std::vector<std::uint8_t> bytes() const {
        std::vector<std::uint8_t> out(rgb.size());
        for (std::size_t i = 0; i < rgb.size(); ++i) out[i] = std::uint8_t(std::clamp(rgb[i], 0.0f, 1.0f) * 255.0f + 0.5f);
        return out;
    }
};

enum class Align { left, centre, right };

/// Labels in DejaVu Sans through FreeType, `size` pixels high, on a baseline.
class TextPainter {
public:
    TextPainter(const char* font, int size) {
        if (FT_Init_FreeType(&lib_) != 0) return;
        if (FT_New_Face(lib_, font, 0, &face_) != 0 || FT_Set_Pixel_Sizes(face_, 0, FT_UInt(size)) != 0) face_ = nullptr;
    }
    ~TextPainter() {
        if (face_ != nullptr) FT_Done_Face(face_);
        if (lib_ != nullptr) FT_Done_FreeType(lib_);
    }
    TextPainter(const TextPainter&) = delete;
    TextPainter& operator=(const TextPainter&) = delete;

    bool ready() const { return face_ != nullptr; }

    void draw(Canvas& canvas, int x, int baseline, const std::string& text, Align align) {
        if (align != Align::left) {
            const int w = advance(text);
            x -= align == Align::centre ? w / 2 : w;
        }
        for (const char ch : text) {
            if (FT_Load_Char(face_, FT_ULong(static_cast<unsigned char>(ch)), FT_LOAD_RENDER) != 0) continue;
            const FT_GlyphSlot g = face_->glyph;
            for (unsigned row = 0; row < g->bitmap.rows; ++row)
                for (unsigned col = 0; col < g->bitmap.width; ++col) {
                    const float a = float(g->bitmap.buffer[std::ptrdiff_t(row) * g->bitmap.pitch + col]) / 255.0f;
                    if (a > 0.0f) canvas.blendWhite(x + g->bitmap_left + int(col), baseline - g->bitmap_top + int(row), a);
                }
            x += int(g->advance.x >> 6);
        }
    }

private:
    int advance(const std::string& text) {
        int w = 0;
        for (const char ch : text)
            if (FT_Load_Char(face_, FT_ULong(static_cast<unsigned char>(ch)), FT_LOAD_DEFAULT) == 0) w += int(face_->glyph->advance.x >> 6);
        return w;
    }
    FT_Library lib_ = nullptr;
    FT_Face face_ = nullptr;
};

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
    Canvas img(W, H);
    const double span = scale.hi - scale.lo;
    float rgb[3];
    for (std::uint32_t y = 0; y < height; ++y)
        for (std::uint32_t x = 0; x < width; ++x) {
            const float v = values[std::size_t(y) * width + x];
            if (std::isfinite(v)) colourOf(span > 0 ? (v - scale.lo) / span : 0.5, scale.diverging, rgb);
            else rgb[0] = rgb[1] = rgb[2] = 0.5f;
            img.set(int(x), int(y), rgb);
        }
    // The colour bar, from lo (left) to hi (right), under the image.
    const int barX0 = 10, barX1 = W - 10;
    for (int x = barX0; x < barX1; ++x) {
        colourOf(double(x - barX0) / double(barX1 - barX0 - 1), scale.diverging, rgb);
        for (int y = barTop; y < barTop + barH; ++y) img.set(x, y, rgb);
    }
    if (TextPainter text(kFont, 13); text.ready()) {
        const int textY = barTop + barH + 14;
        text.draw(img, barX0, textY, label(scale.lo), Align::left);
        if (scale.diverging) text.draw(img, (barX0 + barX1) / 2, textY, "0", Align::centre);
        text.draw(img, barX1, textY, label(scale.hi), Align::right);
        // The title on two lines when it has a parenthesis: each must fit the panel (at least 520 pixels).
        const auto paren = scale.title.find(" (");
        text.draw(img, barX0, textY + 17, scale.title.substr(0, paren), Align::left);
        if (paren != std::string::npos) text.draw(img, barX0, textY + 34, scale.title.substr(paren + 1), Align::left);
    }
    writePng(file, img.bytes(), std::uint32_t(W), std::uint32_t(H), fmt::format("{}: scale [{}, {}]", scale.title, scale.lo, scale.hi));
}

}  // namespace accretion
