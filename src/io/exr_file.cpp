#include "accretion/io/exr_file.h"

#include <iterator>
#include <mutex>
#include <thread>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <fmt/format.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"

namespace accretion {

namespace {

/// OpenEXR compresses and decompresses blocks of lines on its own threads
/// (set once per process; the files are the same for any count).
void useAllCores() {
    static std::once_flag once;
    std::call_once(once, [] { Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency()))); });
}

/// Header attributes every EXR has, kept out of the float attributes a
/// caller copies from one file to another.
bool isStandard(const std::string& name) {
    return name == "channels" || name == "compression" || name == "dataWindow" || name == "displayWindow" ||
           name == "lineOrder" || name == "pixelAspectRatio" || name == "screenWindowCenter" ||
           name == "screenWindowWidth";
}

std::string joined(const float* v, int n) {
    std::string s;
    for (int i = 0; i < n; ++i) {
        if (i) s += ' ';
        fmt::format_to(std::back_inserter(s), "{}", v[i]);
    }
    return s;
}

/// A numeric attribute's floats and OpenEXR type name; false for any other type.
bool floatsOf(const Imf::Attribute& a, std::pair<std::string, std::vector<float>>& out) {
    out.first = a.typeName();
    if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(&a)) out.second = {f->value()};
    else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(&a)) out.second = {float(d->value())};
    else if (const auto* v2 = dynamic_cast<const Imf::V2fAttribute*>(&a)) out.second = {v2->value().x, v2->value().y};
    else if (const auto* v3 = dynamic_cast<const Imf::V3fAttribute*>(&a))
        out.second = {v3->value().x, v3->value().y, v3->value().z};
    else if (const auto* m = dynamic_cast<const Imf::M44fAttribute*>(&a)) out.second.assign(&m->value()[0][0], &m->value()[0][0] + 16);
    else if (const auto* m3 = dynamic_cast<const Imf::M33fAttribute*>(&a)) out.second.assign(&m3->value()[0][0], &m3->value()[0][0] + 9);
    else return false;
    return true;
}

void addFloats(Imf::Header& h, const std::string& name, const std::string& type, const std::vector<float>& v) {
    if (type == "m44f" && v.size() == 16) {
        Imath::M44f m;
        std::copy(v.begin(), v.end(), &m[0][0]);
        h.insert(name, Imf::M44fAttribute(m));
    } else if (type == "m33f" && v.size() == 9) {
        Imath::M33f m;
        std::copy(v.begin(), v.end(), &m[0][0]);
        h.insert(name, Imf::M33fAttribute(m));
    } else if (type == "v2f" && v.size() == 2) h.insert(name, Imf::V2fAttribute(Imath::V2f(v[0], v[1])));
    else if (type == "v3f" && v.size() == 3) h.insert(name, Imf::V3fAttribute(Imath::V3f(v[0], v[1], v[2])));
    else if (type == "float" && v.size() == 1) h.insert(name, Imf::FloatAttribute(v[0]));
    else if (type == "double" && v.size() == 1) h.insert(name, Imf::DoubleAttribute(v[0]));
    else throw InternalError(fmt::format("EXR attribute {}: {} values of type {} cannot be written", name, v.size(), type));
}

}  // namespace

int ExrHeader::channelIndex(const std::string& name) const {
    for (std::size_t c = 0; c < channels.size(); ++c)
        if (channels[c] == name) return int(c);
    return -1;
}

namespace {

/// The most a compression can shrink pixel data: NONE stores it, RLE's runs
/// are 128 bytes in 2, deflate (ZIP, ZIPS, PXR24) reaches 1032:1, B44 a
/// flat 4x4 block of halves in 3 bytes; PIZ and DWA end in run-length
/// Huffman codes, bounded here generously.
double maxCompression(Imf::Compression c) {
    switch (c) {
    case Imf::NO_COMPRESSION: return 1.0;
    case Imf::RLE_COMPRESSION: return 64.0;
    case Imf::ZIPS_COMPRESSION:
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 1032.0;
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION: return 32.0 / 3.0;
    default: return 65536.0;
    }
}

/// Refuse a header whose pixels the file cannot hold, before anything is
/// allocated on its word (a 500-byte file claiming 100000 x 100000 pixels).
void requireHeldBy(const std::filesystem::path& file, const Imf::Header& h) {
    const Imath::Box2i data = h.dataWindow();
    double bytesPerPixel = 0.0;
    for (auto c = h.channels().begin(); c != h.channels().end(); ++c)
        bytesPerPixel += c.channel().type == Imf::HALF ? 2.0 : 4.0;
    const double pixels = (double(data.max.x) - data.min.x + 1.0) * (double(data.max.y) - data.min.y + 1.0);
    std::error_code ec;
    const double size = double(std::filesystem::file_size(file, ec));
    const double most = ec ? 0.0 : size * maxCompression(h.compression());
    if (pixels * bytesPerPixel > most)
        throw InputError(fmt::format("{}: cannot read EXR: its header claims {:.0f}x{:.0f} pixels of {} bytes, more than "
                                     "its {:.0f} bytes can hold (truncated or corrupt)", file.string(),
                                     double(data.max.x) - data.min.x + 1.0, double(data.max.y) - data.min.y + 1.0,
                                     bytesPerPixel, size));
}

}  // namespace

struct ExrReader::File {
    Imf::InputFile in;
    explicit File(const std::filesystem::path& path) : in(path.c_str()) {}
};

ExrReader::ExrReader(const std::filesystem::path& file) : path_(file) {
    useAllCores();
    try {
        file_ = std::make_unique<File>(file);
        const Imf::Header& h = file_->in.header();
        const Imath::Box2i data = h.dataWindow(), display = h.displayWindow();
        ExrHeader& out = header_;
        out.fullWidth = std::uint32_t(display.max.x - display.min.x + 1);
        out.fullHeight = std::uint32_t(display.max.y - display.min.y + 1);
        out.x0 = data.min.x - display.min.x;
        out.y0 = data.min.y - display.min.y;
        out.width = std::uint32_t(data.max.x - data.min.x + 1);
        out.height = std::uint32_t(data.max.y - data.min.y + 1);
        for (auto c = h.channels().begin(); c != h.channels().end(); ++c) {
            out.channels.push_back(c.name());
            out.types.push_back(c.channel().type == Imf::UINT   ? ExrChannelType::uint32
                                : c.channel().type == Imf::HALF ? ExrChannelType::half
                                                                : ExrChannelType::float32);
        }
        if (data.max.x < data.min.x || data.max.y < data.min.y || display.max.x < display.min.x ||
            display.max.y < display.min.y)
            throw InputError(fmt::format("{}: cannot read EXR: an empty or inverted data or display window", file.string()));
        requireHeldBy(file, h);
        for (auto a = h.begin(); a != h.end(); ++a) {
            const std::string name = a.name();
            std::pair<std::string, std::vector<float>> floats;
            if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a.attribute())) {
                out.strings[name] = s->value();
                out.printed[name] = s->value();
            } else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a.attribute())) {
                out.printed[name] = std::to_string(i->value());
            } else if (floatsOf(a.attribute(), floats)) {
                out.printed[name] = joined(floats.second.data(), int(floats.second.size()));
                if (!isStandard(name)) out.floats[name] = std::move(floats);
            }
        }
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: cannot read EXR: {}", file.string(), e.what()));
    }
}

ExrReader::~ExrReader() = default;

std::vector<std::uint32_t> ExrReader::pixels(const std::vector<std::string>& channels, bool asFloat) {
    const std::size_t n = channels.size(), count = std::size_t(header_.width) * header_.height;
    std::vector<std::uint32_t> bits;
    try {
        bits.resize(count * n);
    } catch (const std::bad_alloc&) {
        throw InputError(fmt::format("{}: out of memory for its {}x{} pixels of {} channels", path_.string(), header_.width,
                                     header_.height, n));
    }
    const Imath::Box2i data = file_->in.header().dataWindow();
    const std::size_t xStride = n * 4, yStride = xStride * header_.width;
    // The slice's base is where pixel (0, 0) of the file's coordinates would lie.
    char* origin = reinterpret_cast<char*>(bits.data()) - std::ptrdiff_t(data.min.x) * std::ptrdiff_t(xStride) -
                   std::ptrdiff_t(data.min.y) * std::ptrdiff_t(yStride);
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < n; ++c) {
        const int k = header_.channelIndex(channels[c]);
        if (k < 0) throw InputError(fmt::format("{}: no channel {}", path_.string(), channels[c]));
        const ExrChannelType t = header_.types[std::size_t(k)];
        if (!asFloat && t == ExrChannelType::half)
            throw InputError(fmt::format("{}: channel {} is not 32-bit", path_.string(), channels[c]));
        const Imf::PixelType type = !asFloat && t == ExrChannelType::uint32 ? Imf::UINT : Imf::FLOAT;
        fb.insert(channels[c], Imf::Slice(type, origin + c * 4, xStride, yStride));
    }
    try {
        file_->in.setFrameBuffer(fb);
        file_->in.readPixels(data.min.y, data.max.y);
    } catch (const std::exception& e) {
        throw InputError(fmt::format("{}: cannot read EXR pixels: {}", path_.string(), e.what()));
    }
    return bits;
}

ExrHeader readExrHeader(const std::filesystem::path& file) { return ExrReader(file).header(); }

void writeExr(const std::filesystem::path& file, const ExrImage& image) {
    useAllCores();
    const std::size_t n = image.channels.size();
    ACC_CHECK(image.uints.size() == n && image.bits != nullptr && image.width > 0 && image.height > 0);
    const std::uint32_t fullWidth = image.fullWidth ? image.fullWidth : image.width;
    const std::uint32_t fullHeight = image.fullHeight ? image.fullHeight : image.height;
    const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i(int(fullWidth) - 1, int(fullHeight) - 1));
    const Imath::Box2i data(Imath::V2i(image.x0, image.y0),
                            Imath::V2i(image.x0 + int(image.width) - 1, image.y0 + int(image.height) - 1));
    Imf::Header h(display, data, 1.0f, Imath::V2f(0.0f, 0.0f), 1.0f, Imf::INCREASING_Y, Imf::ZIP_COMPRESSION);
    for (std::size_t c = 0; c < n; ++c) h.channels().insert(image.channels[c], Imf::Channel(image.uints[c] ? Imf::UINT : Imf::FLOAT));
    for (const auto& [k, v] : image.strings) h.insert(k, Imf::StringAttribute(v));
    for (const auto& [k, tv] : image.floats) addFloats(h, k, tv.first, tv.second);

    const std::size_t xStride = n * 4, yStride = xStride * image.width;
    // OpenEXR's slices take a non-const base; the pixels are only read.
    char* origin = const_cast<char*>(reinterpret_cast<const char*>(image.bits)) - std::ptrdiff_t(image.x0) * std::ptrdiff_t(xStride) -
                   std::ptrdiff_t(image.y0) * std::ptrdiff_t(yStride);
    Imf::FrameBuffer fb;
    for (std::size_t c = 0; c < n; ++c)
        fb.insert(image.channels[c], Imf::Slice(image.uints[c] ? Imf::UINT : Imf::FLOAT, origin + c * 4, xStride, yStride));
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        try {
            Imf::OutputFile out(tmp.c_str(), h);
            out.setFrameBuffer(fb);
            out.writePixels(int(image.height));
        } catch (const std::exception& e) {
            throw InputError(fmt::format("{}: cannot write EXR: {}", file.string(), e.what()));
        }
    });
}

}  // namespace accretion
