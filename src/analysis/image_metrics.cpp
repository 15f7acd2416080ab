#include "accretion/analysis/image_metrics.h"

#include <bit>
#include <fstream>

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/io/exr_file.h"

namespace accretion {

void requireFinitePixels(const std::vector<Vec3>& pixels, const std::string& file, const char* layer, std::uint32_t width) {
    for (std::size_t p = 0; p < pixels.size(); ++p)
        if (!(std::isfinite(pixels[p].x) && std::isfinite(pixels[p].y) && std::isfinite(pixels[p].z)))
            throw InputError(fmt::format("{}: {} is not finite at pixel ({}, {}): the experiments measure finite images", file,
                                         layer, p % width, p / width));
}

double flickerRelMse(const std::vector<Vec3>& x, const std::vector<Vec3>& xPrev, const std::vector<Vec3>& ref,
                     const std::vector<Vec3>& refPrev, double* change, double eps) {
    ACC_CHECK(x.size() == ref.size() && xPrev.size() == ref.size() && refPrev.size() == ref.size());
    double flicker = 0.0, own = 0.0;
    for (std::size_t p = 0; p < ref.size(); ++p)
        for (int c = 0; c < 3; ++c) {
            const double r = ref[p][c], dr = r - double(refPrev[p][c]);
            const double dx = double(x[p][c]) - double(xPrev[p][c]), w = 1.0 / (r * r + eps);
            flicker += (dx - dr) * (dx - dr) * w;
            own += dr * dr * w;
        }
    const double n = 3.0 * double(std::max<std::size_t>(ref.size(), 1));
    if (change) *change = own / n;
    return flicker / n;
}

ErrorMetrics computeErrors(const std::vector<Vec3>& x, const std::vector<Vec3>& ref, const std::vector<Vec3>* refStderr,
                           double eps, double tolerance) {
    ACC_CHECK(x.size() == ref.size());
    ACC_CHECK(!refStderr || refStderr->size() == ref.size());
    ErrorMetrics m;
    m.pixels = x.size();
    if (x.empty()) return m;
    double rel = 0.0, mse = 0.0, mape = 0.0, floor = 0.0;
    auto finite = [](const Vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (!finite(x[i]) || !finite(ref[i]) || (refStderr && !finite((*refStderr)[i]))) {
            if (m.nonFinite++ < ErrorMetrics::kNonFiniteListed) m.firstNonFinite.push_back(i);
            continue;
        }
        const bool lit = ref[i] != Vec3(0.0f);
        m.lit += lit;
        m.identical += lit && x[i] == ref[i];
        bool within = lit;
        for (int c = 0; c < 3; ++c) {
            const double r = ref[i][c];
            const double d = double(x[i][c]) - r;
            rel += d * d / (r * r + eps);
            mse += d * d;
            mape += std::fabs(d) / (std::fabs(r) + eps);
            within = within && std::fabs(d) <= tolerance * std::fabs(r);
            if (refStderr) {
                const double s = (*refStderr)[i][c];
                floor += s * s / (r * r + eps);
            }
        }
        m.withinTolerance += within;
    }
    m.pixels = x.size() - m.nonFinite;
    if (m.pixels == 0) return m;
    const double n = 3.0 * double(m.pixels);
    m.relMSE = rel / n;
    m.MSE = mse / n;
    m.MAPE = mape / n;
    m.relMSEFloor = floor / n;
    return m;
}

namespace {

/// Refuse a file that is not an OpenEXR file, by its magic: a PNG or JPEG
/// is display-referred and 8-bit, not a measurement.
void requireExr(const std::filesystem::path& file) {
    std::ifstream f = openInputFile(file, "image");
    unsigned char magic[4] = {};
    f.read(reinterpret_cast<char*>(magic), 4);
    if (!(magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01))
        throw InputError(fmt::format("{}: not an OpenEXR file: images are compared as scene-referred floats (EXR), "
                                     "not display-referred 8-bit previews", file.string()));
}

std::vector<std::string> layerChannels(const std::string& layer) {
    if (layer.empty()) return {"R", "G", "B"};
    return {layer + ".R", layer + ".G", layer + ".B"};
}

}  // namespace

bool exrHasLayer(const std::filesystem::path& file, const std::string& layer) {
    ExrHeader h;
    try {
        h = readExrHeader(file);
    } catch (const InputError&) {
        return false;
    }
    for (const std::string& c : layerChannels(layer))
        if (h.channelIndex(c) < 0) return false;
    return true;
}

namespace {

/// The three channels `channels(header)` names, as floats, from one reading of the file.
template <class Channels>
RgbLayer readChannels(const std::filesystem::path& file, Channels&& channels) {
    requireExr(file);
    ExrReader reader(file);
    const ExrHeader& h = reader.header();
    const std::vector<std::string> names = channels(h);
    ACC_CHECK(names.size() == 3);
    for (const std::string& name : names)
        if (h.channelIndex(name) < 0)
            throw InputError(fmt::format("{}: no channel '{}' (it has {})", file.string(), name, fmt::join(h.channels, ", ")));
    RgbLayer out{h.fullWidth, h.fullHeight, h.x0, h.y0, h.width, h.height, {}};
    // Each channel read once (a layer of one channel names it three times).
    std::vector<std::string> unique;
    std::size_t slot[3];
    for (int c = 0; c < 3; ++c) {
        const auto it = std::find(unique.begin(), unique.end(), names[std::size_t(c)]);
        slot[c] = std::size_t(it - unique.begin());
        if (it == unique.end()) unique.push_back(names[std::size_t(c)]);
    }
    const std::vector<std::uint32_t> bits = reader.pixels(unique, true);
    const std::size_t pixels = std::size_t(out.dataWidth) * out.dataHeight, n = unique.size();
    out.rgb.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) out.rgb[p][c] = std::bit_cast<float>(bits[p * n + slot[c]]);
    return out;
}

}  // namespace

RgbLayer readExrChannels(const std::filesystem::path& file, const std::vector<std::string>& names) {
    return readChannels(file, [&](const ExrHeader&) { return names; });
}

std::vector<Vec3> RgbLayer::window(int x, int y, std::uint32_t w, std::uint32_t h) const {
    ACC_CHECK(x >= x0 && y >= y0 && x + int(w) <= x0 + int(dataWidth) && y + int(h) <= y0 + int(dataHeight));
    std::vector<Vec3> out;
    out.reserve(std::size_t(w) * h);
    for (int py = y; py < y + int(h); ++py)
        for (int px = x; px < x + int(w); ++px) out.push_back(rgb[std::size_t(py - y0) * dataWidth + (px - x0)]);
    return out;
}

std::vector<std::uint32_t> readExrUintChannel(const std::filesystem::path& file, const std::string& name) {
    ExrReader reader(file);
    const int c = reader.header().channelIndex(name);
    if (c < 0 || reader.header().types[std::size_t(c)] != ExrChannelType::uint32) return {};
    return reader.pixels({name}, false);
}

RgbLayer readExrLayer(const std::filesystem::path& file, const std::string& layer) {
    return readChannels(file, [&](const ExrHeader& h) {
        std::vector<std::string> names = layerChannels(layer);
        if (!layer.empty() && h.channelIndex(names[0]) < 0 && h.channelIndex(layer) >= 0)
            names = {layer, layer, layer};  // a channel of its own: spp, depth.Z
        return names;
    });
}

std::map<std::string, std::string> readExrAttributes(const std::filesystem::path& file) {
    return readExrHeader(file).printed;  // strings as they are, numbers and matrices printed
}

}  // namespace accretion
