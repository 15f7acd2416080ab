#include "accretion/io/exr_output.h"

#include <cstring>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/io/atomic_file.h"
#include "accretion/render/gbuffer.h"

namespace accretion {

namespace OIIO = OIIO_NAMESPACE;

void writeFrameExr(const std::filesystem::path& file, const FrameImage& img, bool withErrors, const OutputMetadata& metadata) {
    std::vector<std::string> names = {"R", "G", "B", "Le.R", "Le.G", "Le.B", "Lr.R", "Lr.G", "Lr.B",
                                      "depth.Z", "N.X", "N.Y", "N.Z", "particle.id"};
    if (withErrors)
        for (const char* n : {"Lr_stderr.R", "Lr_stderr.G", "Lr_stderr.B", "spp"}) names.push_back(n);
    const int nch = static_cast<int>(names.size());
    const int idChannel = 13;

    OIIO::ImageSpec spec(int(img.width), int(img.height), nch, OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.channelformats.assign(nch, OIIO::TypeDesc::FLOAT);
    spec.channelformats[idChannel] = OIIO::TypeDesc::UINT;
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : metadata) spec.attribute("accretion:" + k, v);

    // Interleaved pixels in the native per-channel formats (all 4 bytes).
    const std::size_t pixels = std::size_t(img.width) * img.height;
    std::vector<std::uint32_t> buf(pixels * nch);
    auto putF = [&](std::size_t px, int ch, float v) { std::memcpy(&buf[px * nch + ch], &v, 4); };
    for (std::size_t px = 0; px < pixels; ++px) {
        for (int c = 0; c < 3; ++c) {
            putF(px, c, img.L[px][c]);
            putF(px, 3 + c, img.Le[px][c]);
            putF(px, 6 + c, img.lighting.Lr[px][c]);
            putF(px, 10 + c, img.normal[px][c]);
        }
        putF(px, 9, img.depth[px]);
        buf[px * nch + idChannel] = img.particle[px];
        if (withErrors) {
            for (int c = 0; c < 3; ++c) putF(px, 14 + c, img.lighting.Lr_stderr[px][c]);
            putF(px, 17, img.lighting.spp[px]);
        }
    }

    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("openexr");
        if (!out) throw InternalError("OpenImageIO has no OpenEXR writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UNKNOWN, buf.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write EXR: {}", file.string(), out->geterror()));
    });
}

void writePreviewPng(const std::filesystem::path& file, const std::vector<Vec3>& rgb, std::uint32_t width,
                     std::uint32_t height, bool autoExposure, double exposure) {
    double scale = std::exp2(exposure);
    if (autoExposure) {
        std::vector<float> lum;
        lum.reserve(rgb.size());
        for (const Vec3& c : rgb)
            if (const float y = luminance(c); y > 0.0f && std::isfinite(y)) lum.push_back(y);
        if (!lum.empty()) {
            const std::size_t k = std::min(lum.size() - 1, std::size_t(0.995 * double(lum.size())));
            std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
            if (lum[k] > 0.0f) scale /= lum[k];
        }
    }
    auto encode = [](float v) {
        v = std::clamp(v, 0.0f, 1.0f);
        v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
        return static_cast<std::uint8_t>(std::lround(v * 255.0f));
    };
    std::vector<std::uint8_t> px(rgb.size() * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i)
        for (int c = 0; c < 3; ++c) px[3 * i + c] = encode(float(scale) * rgb[i][c]);

    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::UINT8);
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("png");
        if (!out) throw InternalError("OpenImageIO has no PNG writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, px.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write PNG: {}", file.string(), out->geterror()));
    });
}

}  // namespace accretion
