#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include "accretion/scene/settings.h"

namespace accretion {

/// A window of the image in pixels, half-open: [x0, x1) x [y0, y1) (pbrt's
/// pixel bounds). render.crop renders only it; the EXR stores it as its data
/// window, inside the display window of the whole image.
struct PixelWindow {
    std::uint32_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;

    static PixelWindow whole(std::uint32_t width, std::uint32_t height) { return {0, width, 0, height}; }
    /// render.crop of the settings, or the whole image when it is empty.
    static PixelWindow of(const Settings& s) { return of(s.render, s.camera.width, s.camera.height); }
    static PixelWindow of(const RenderSettings& render, std::uint32_t width, std::uint32_t height) {
        const std::vector<double>& c = render.crop;
        if (c.size() != 4) return whole(width, height);
        return {std::uint32_t(c[0]), std::uint32_t(c[1]), std::uint32_t(c[2]), std::uint32_t(c[3])};
    }

    std::uint32_t width() const { return x1 - x0; }
    std::uint32_t height() const { return y1 - y0; }
    std::size_t pixels() const { return std::size_t(width()) * height(); }
    bool contains(std::uint32_t x, std::uint32_t y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
    bool contains(const PixelWindow& w) const { return w.x0 >= x0 && w.x1 <= x1 && w.y0 >= y0 && w.y1 <= y1; }
    /// Where pixel (x, y) of the image lies in a buffer of the window's pixels, row by row.
    std::size_t index(std::uint32_t x, std::uint32_t y) const { return std::size_t(y - y0) * width() + (x - x0); }
    bool isWhole(std::uint32_t w, std::uint32_t h) const { return x0 == 0 && y0 == 0 && x1 == w && y1 == h; }
    bool operator==(const PixelWindow&) const = default;
};

/// The window's values of a row-major image `width` pixels wide, row by row.
template <class T>
std::vector<T> cropPixels(const std::vector<T>& image, std::uint32_t width, const PixelWindow& w) {
    std::vector<T> out;
    out.reserve(w.pixels());
    for (std::uint32_t y = w.y0; y < w.y1; ++y)
        for (std::uint32_t x = w.x0; x < w.x1; ++x) out.push_back(image[std::size_t(y) * width + x]);
    return out;
}

}  // namespace accretion
