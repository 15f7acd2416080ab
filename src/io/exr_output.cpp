#include "accretion/io/exr_output.h"

#include <bit>
#include <cstring>
#include <functional>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/io/exr_file.h"
#include "accretion/io/false_colour.h"
#include "accretion/io/png_file.h"
#include "accretion/render/gbuffer.h"

namespace accretion {

ExrCameraMatrices exrCameraMatrices(const CameraPose& c, std::uint32_t width, std::uint32_t height) {
    const DVec3 axis[3] = {c.right, c.up, c.forward};
    double cam[4][4] = {};  // column vectors: camera = cam * world
    for (int r = 0; r < 3; ++r) {
        for (int k = 0; k < 3; ++k) cam[r][k] = axis[r][k];
        cam[r][3] = -glm::dot(axis[r], c.eye);
    }
    cam[3][3] = 1.0;
    const double aspect = double(width) / double(height);
    const double ndc[4][4] = {{0.5 / (c.tanHalfFov * aspect), 0.0, 0.5 - c.jitterX / double(width), 0.0},
                              {0.0, -0.5 / c.tanHalfFov, 0.5 - c.jitterY / double(height), 0.0},
                              {0.0, 0.0, 1.0, 0.0},
                              {0.0, 0.0, 1.0, 0.0}};
    ExrCameraMatrices m;
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) {
            double sum = 0.0;
            for (int j = 0; j < 4; ++j) sum += ndc[r][j] * cam[j][k];
            // Imath stores the transpose (row vectors): element [k][r].
            m.worldToCamera[std::size_t(4 * k + r)] = float(cam[r][k]);
            m.worldToNDC[std::size_t(4 * k + r)] = float(sum);
        }
    return m;
}

namespace {

/// The camera's standard attributes (OpenEXR's worldToCamera and worldToNDC)
/// and its jitter in pixels.
void setCameraAttributes(ExrImage& exr, const CameraPose& c, std::uint32_t width, std::uint32_t height) {
    const ExrCameraMatrices m = exrCameraMatrices(c, width, height);
    exr.floats["worldToCamera"] = {"m44f", std::vector<float>(m.worldToCamera.begin(), m.worldToCamera.end())};
    exr.floats["worldToNDC"] = {"m44f", std::vector<float>(m.worldToNDC.begin(), m.worldToNDC.end())};
    exr.floats["accretion:jitter"] = {"v2f", {float(c.jitterX), float(c.jitterY)}};
}

}  // namespace

void writeFrameExr(const std::filesystem::path& file, const FrameImage& img, bool withErrors, const OutputMetadata& metadata) {
    // One entry per channel: name, UINT or FLOAT, and the value of pixel px.
    struct Channel {
        std::string name;
        bool isUint;
        std::function<std::uint32_t(std::size_t)> bits;
    };
    std::vector<Channel> channels;
    auto addVec = [&](const std::string& prefix, const char* const* suffix, const std::vector<Vec3>& v) {
        for (int c = 0; c < 3; ++c)
            channels.push_back({prefix + suffix[c], false, [&v, c](std::size_t px) { return std::bit_cast<std::uint32_t>(v[px][c]); }});
    };
    auto addFloat = [&](const std::string& name, const std::vector<float>& v) {
        channels.push_back({name, false, [&v](std::size_t px) { return std::bit_cast<std::uint32_t>(v[px]); }});
    };
    static const char* const rgb[3] = {"R", "G", "B"};
    static const char* const dotRgb[3] = {".R", ".G", ".B"};
    static const char* const xyz[3] = {".X", ".Y", ".Z"};
    addVec("", rgb, img.L);
    addVec("Le", dotRgb, img.Le);
    addVec("Lr", dotRgb, img.lighting.Lr);
    addFloat("depth.Z", img.depth);
    addVec("N", xyz, img.normal);
    channels.push_back({"particle.id", true, [&](std::size_t px) { return img.particle[px]; }});
    if (!img.lighting.rejected.empty()) addFloat("rejected", img.lighting.rejected);
    if (withErrors) {
        addVec("Lr_stderr", dotRgb, img.lighting.Lr_stderr);
        addFloat("spp", img.lighting.spp);
    }
    if (!img.reservoirs.empty()) {
        addFloat("restir.W", img.reservoirs.W);
        addFloat("restir.M", img.reservoirs.M);
        channels.push_back({"restir.light", true, [&](std::size_t px) { return img.reservoirs.light[px]; }});
        addFloat("restir.p_hat", img.reservoirs.p_hat);
    }
    for (const Heatmap& h : img.heatmaps) addFloat(h.name, h.values);
    const int nch = static_cast<int>(channels.size());

    // The data window is the rendered window (render.crop), inside the
    // display window of the whole image; the layers hold its pixels.
    const PixelWindow& w = img.window;
    ACC_CHECK(img.L.size() == w.pixels());
    // Interleaved pixels in the native per-channel formats (all 4 bytes).
    std::vector<std::uint32_t> buf(w.pixels() * nch);
    for (std::size_t k = 0; k < w.pixels(); ++k)
        for (int ch = 0; ch < nch; ++ch) buf[k * nch + ch] = channels[ch].bits(k);

    ExrImage exr;
    exr.fullWidth = img.width;
    exr.fullHeight = img.height;
    exr.x0 = int(w.x0);
    exr.y0 = int(w.y0);
    exr.width = w.width();
    exr.height = w.height();
    for (const Channel& c : channels) {
        exr.channels.push_back(c.name);
        exr.uints.push_back(c.isUint);
    }
    exr.bits = buf.data();
    for (const auto& [key, v] : metadata) exr.strings["accretion:" + key] = v;
    setCameraAttributes(exr, img.camera, img.width, img.height);
    writeExr(file, exr);
}

void writeChannelsExr(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                      const std::vector<FloatChannel>& channels, const OutputMetadata& metadata, DataWindow window) {
    const std::size_t nch = channels.size(), pixels = std::size_t(width) * height;
    std::vector<std::uint32_t> buf(pixels * nch);
    for (std::size_t ch = 0; ch < nch; ++ch) {
        ACC_CHECK(channels[ch].values.size() == pixels);
        for (std::size_t px = 0; px < pixels; ++px) buf[px * nch + ch] = std::bit_cast<std::uint32_t>(channels[ch].values[px]);
    }
    ExrImage exr;
    exr.fullWidth = window.fullWidth;
    exr.fullHeight = window.fullHeight;
    if (window.fullWidth > 0) {
        exr.x0 = window.x;
        exr.y0 = window.y;
    }
    exr.width = width;
    exr.height = height;
    for (const FloatChannel& c : channels) {
        exr.channels.push_back(c.name);
        exr.uints.push_back(false);
    }
    exr.bits = buf.data();
    for (const auto& [key, v] : metadata) exr.strings["accretion:" + key] = v;
    writeExr(file, exr);
}

namespace {

/// The 99.5th percentile of the positive finite values (0 if there are none).
float percentile995(std::vector<float> v) {
    std::erase_if(v, [](float x) { return !(x > 0.0f) || !std::isfinite(x); });
    if (v.empty()) return 0.0f;
    const std::size_t k = std::min(v.size() - 1, std::size_t(0.995 * double(v.size())));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k];
}

}  // namespace

void writeRgb8Png(const std::filesystem::path& file, const std::vector<std::uint8_t>& px, std::uint32_t width,
                  std::uint32_t height) {
    writePng(file, px, width, height);
}

void writeHeatmapPng(const std::filesystem::path& file, const std::vector<float>& values, std::uint32_t width,
                     std::uint32_t height, const std::string& title) {
    const float p = percentile995(values);
    writeFalseColourPng(file, values, width, height, {0.0, p > 0.0f ? double(p) : 1.0, false, title + " (scale: 99.5th percentile)"});
}


std::size_t RawExr::channel(const std::string& name) const {
    for (std::size_t c = 0; c < channels.size(); ++c)
        if (channels[c] == name) return c;
    throw InputError(fmt::format("{}: no channel {}", file, name));
}

float RawExr::value(std::size_t px, std::size_t c) const { return std::bit_cast<float>(bits[px * channels.size() + c]); }

void RawExr::set(std::size_t px, std::size_t c, float v) { bits[px * channels.size() + c] = std::bit_cast<std::uint32_t>(v); }

RawExr readRawExr(const std::filesystem::path& file) {
    ExrReader reader(file);
    const ExrHeader& h = reader.header();
    RawExr exr;
    exr.file = file.string();
    exr.width = h.width;
    exr.height = h.height;
    exr.channels = h.channels;
    for (const ExrChannelType t : h.types) {
        if (t == ExrChannelType::half)
            throw InputError(fmt::format("{}: channel {} is not 32-bit", file.string(), h.channels[exr.uints.size()]));
        exr.uints.push_back(t == ExrChannelType::uint32);
    }
    exr.attributes = h.strings;
    exr.floatAttributes = h.floats;
    exr.bits = reader.pixels(h.channels, false);
    return exr;
}

void writeRawExr(const std::filesystem::path& file, const RawExr& raw) {
    ExrImage exr;
    exr.width = raw.width;
    exr.height = raw.height;
    exr.channels = raw.channels;
    exr.uints = raw.uints;
    exr.bits = raw.bits.data();
    exr.strings = raw.attributes;
    exr.floats = raw.floatAttributes;
    writeExr(file, exr);
}

}  // namespace accretion
