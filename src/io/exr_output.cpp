#include "accretion/io/exr_output.h"

#include <bit>
#include <cstring>
#include <functional>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/false_colour.h"
#include "accretion/render/gbuffer.h"

namespace accretion {

namespace OIIO = OIIO_NAMESPACE;

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

/// The EXR's data window at (x, y) inside a display window of the whole image.
void setDataWindow(OIIO::ImageSpec& spec, int x, int y, std::uint32_t fullWidth, std::uint32_t fullHeight) {
    spec.x = x;
    spec.y = y;
    spec.full_x = spec.full_y = 0;
    spec.full_width = int(fullWidth);
    spec.full_height = int(fullHeight);
}

void setCameraAttributes(OIIO::ImageSpec& spec, const CameraPose& c, std::uint32_t width, std::uint32_t height) {
    const ExrCameraMatrices m = exrCameraMatrices(c, width, height);
    spec.attribute("worldToCamera", OIIO::TypeMatrix44, m.worldToCamera.data());
    spec.attribute("worldToNDC", OIIO::TypeMatrix44, m.worldToNDC.data());
    const float jitter[2] = {float(c.jitterX), float(c.jitterY)};
    spec.attribute("accretion:jitter", OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::VEC2), jitter);
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
    // display window of the whole image.
    const PixelWindow w = img.window.pixels() ? img.window : PixelWindow::whole(img.width, img.height);
    OIIO::ImageSpec spec(int(w.width()), int(w.height()), nch, OIIO::TypeDesc::FLOAT);
    setDataWindow(spec, int(w.x0), int(w.y0), img.width, img.height);
    spec.channelnames.clear();
    spec.channelformats.clear();
    for (const Channel& c : channels) {
        spec.channelnames.push_back(c.name);
        spec.channelformats.push_back(c.isUint ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT);
    }
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : metadata) spec.attribute("accretion:" + k, v);
    setCameraAttributes(spec, img.camera, img.width, img.height);

    // Interleaved pixels in the native per-channel formats (all 4 bytes).
    std::vector<std::uint32_t> buf(w.pixels() * nch);
    std::size_t k = 0;
    for (std::uint32_t y = w.y0; y < w.y1; ++y)
        for (std::uint32_t x = w.x0; x < w.x1; ++x, ++k)
            for (int ch = 0; ch < nch; ++ch) buf[k * nch + ch] = channels[ch].bits(std::size_t(y) * img.width + x);

    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("openexr");
        if (!out) throw InternalError("OpenImageIO has no OpenEXR writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UNKNOWN, buf.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write EXR: {}", file.string(), out->geterror()));
    });
}

void writeChannelsExr(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                      const std::vector<FloatChannel>& channels, const OutputMetadata& metadata, DataWindow window) {
    const int nch = static_cast<int>(channels.size());
    OIIO::ImageSpec spec(int(width), int(height), nch, OIIO::TypeDesc::FLOAT);
    if (window.fullWidth > 0) setDataWindow(spec, window.x, window.y, window.fullWidth, window.fullHeight);
    spec.channelnames.clear();
    for (const FloatChannel& c : channels) spec.channelnames.push_back(c.name);
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : metadata) spec.attribute("accretion:" + k, v);
    const std::size_t pixels = std::size_t(width) * height;
    std::vector<float> buf(pixels * nch);
    for (int ch = 0; ch < nch; ++ch) {
        ACC_CHECK(channels[ch].values.size() == pixels);
        for (std::size_t px = 0; px < pixels; ++px) buf[px * nch + ch] = channels[ch].values[px];
    }
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("openexr");
        if (!out) throw InternalError("OpenImageIO has no OpenEXR writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, buf.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write EXR: {}", file.string(), out->geterror()));
    });
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
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::UINT8);
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("png");
        if (!out) throw InternalError("OpenImageIO has no PNG writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UINT8, px.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write PNG: {}", file.string(), out->geterror()));
    });
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
    auto in = OIIO::ImageInput::open(file.string());
    if (!in) throw InputError(fmt::format("{}: cannot read EXR: {}", file.string(), OIIO::geterror()));
    const OIIO::ImageSpec& spec = in->spec();
    RawExr exr;
    exr.file = file.string();
    exr.width = static_cast<std::uint32_t>(spec.width);
    exr.height = static_cast<std::uint32_t>(spec.height);
    exr.channels = spec.channelnames;
    for (int c = 0; c < spec.nchannels; ++c) {
        const OIIO::TypeDesc t = spec.channelformat(c);
        if (t.size() != 4) throw InputError(fmt::format("{}: channel {} is not 32-bit", file.string(), spec.channelnames[c]));
        exr.uints.push_back(t == OIIO::TypeDesc::UINT);
    }
    for (const auto& p : spec.extra_attribs) {
        if (p.type() == OIIO::TypeDesc::STRING) exr.attributes[p.name().string()] = p.get_string();
        if (p.type().basetype == OIIO::TypeDesc::FLOAT) {
            const auto* v = static_cast<const float*>(p.data());
            const std::size_t n = std::size_t(p.nvalues()) * p.type().numelements() * p.type().aggregate;
            exr.floatAttributes[p.name().string()] = {p.type().c_str(), std::vector<float>(v, v + n)};
        }
    }
    exr.bits.resize(std::size_t(exr.width) * exr.height * exr.channels.size());
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UNKNOWN, exr.bits.data()))
        throw InputError(fmt::format("{}: cannot read EXR pixels: {}", file.string(), in->geterror()));
    return exr;
}

void writeRawExr(const std::filesystem::path& file, const RawExr& exr) {
    OIIO::ImageSpec spec(int(exr.width), int(exr.height), int(exr.channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = exr.channels;
    spec.channelformats.clear();
    for (const bool u : exr.uints) spec.channelformats.push_back(u ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    for (const auto& [k, v] : exr.attributes) spec.attribute(k, v);
    for (const auto& [k, tv] : exr.floatAttributes) spec.attribute(k, OIIO::TypeDesc(tv.first), tv.second.data());
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        auto out = OIIO::ImageOutput::create("openexr");
        if (!out) throw InternalError("OpenImageIO has no OpenEXR writer");
        if (!out->open(tmp.string(), spec) || !out->write_image(OIIO::TypeDesc::UNKNOWN, exr.bits.data()) || !out->close())
            throw InputError(fmt::format("{}: cannot write EXR: {}", file.string(), out->geterror()));
    });
}

}  // namespace accretion
