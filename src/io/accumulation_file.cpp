#include "accretion/io/accumulation_file.h"

#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/core/atomic_file.h"

namespace accretion {
namespace {

constexpr char kMagic[8] = {'A', 'C', 'C', 'R', 'A', 'C', 'C', '1'};

template <class T> void put(std::string& out, const T* data, std::size_t count) {
    out.append(reinterpret_cast<const char*>(data), sizeof(T) * count);
}

/// Reads from a byte buffer, failing with the file's name when it runs out.
class Reader {
public:
    Reader(const std::string& bytes, const std::filesystem::path& file) : bytes_(bytes), file_(file) {}
    template <class T> void get(T* data, std::size_t count) {
        const std::size_t size = sizeof(T) * count;
        if (bytes_.size() - pos_ < size)
            throw InputError(fmt::format("{}: truncated accumulation file ({} bytes, more expected at byte {})",
                                         file_.string(), bytes_.size(), pos_));
        std::memcpy(static_cast<void*>(data), bytes_.data() + pos_, size);
        pos_ += size;
    }
    std::size_t position() const { return pos_; }

private:
    const std::string& bytes_;
    const std::filesystem::path& file_;
    std::size_t pos_ = 0;
};

}  // namespace

std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t h) {
    for (const char c : bytes) {
        h ^= static_cast<unsigned char>(c);
        h *= 0x100000001b3ull;
    }
    return h;
}

void writeAccumulationFile(const std::filesystem::path& file, const AccumulationFile& content) {
    const Accumulation& a = content.acc;
    nlohmann::json header = content.header;
    header["width"] = a.width;
    header["height"] = a.height;
    header["window"] = {a.window.x0, a.window.x1, a.window.y0, a.window.y1};
    header["next_chunk"] = a.nextChunk;
    header["band_rows"] = a.bandRows;
    header["band_cols"] = a.bandCols;
    const std::string h = header.dump();
    std::string out;
    const std::size_t px = a.pixels();
    out.reserve(8 + 8 + h.size() + px * (6 * 8 + 4 + 1 + 4) + 8);
    out.append(kMagic, 8);
    const std::uint64_t headerSize = h.size();
    put(out, &headerSize, 1);
    out += h;
    put(out, a.sum.data(), px);
    put(out, a.sumSq.data(), px);
    put(out, a.n.data(), px);
    put(out, a.done.data(), px);
    put(out, a.rejected.data(), px);
    const std::uint64_t check = fnv1a64(out);
    put(out, &check, 1);
    writeFileAtomic(file, out);
}

AccumulationFile readAccumulationFile(const std::filesystem::path& file) {
    return parseAccumulationFile(readWholeFile(file, "accumulation file"), file);
}

AccumulationFile parseAccumulationFile(const std::string& bytes, const std::filesystem::path& file) {
    if (bytes.size() < 8 + 8 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
        throw InputError(fmt::format("{}: not an accretion accumulation file (checkpoint or shard)", file.string()));
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
    if (fnv1a64(std::string_view(bytes.data(), bytes.size() - 8)) != stored)
        throw InputError(fmt::format("{}: corrupted accumulation file (checksum mismatch)", file.string()));

    Reader r(bytes, file);
    char magic[8];
    r.get(magic, 8);
    std::uint64_t headerSize = 0;
    r.get(&headerSize, 1);
    if (headerSize > bytes.size()) throw InputError(fmt::format("{}: corrupted accumulation header", file.string()));
    std::string h(headerSize, '\0');
    r.get(h.data(), headerSize);
    AccumulationFile f;
    try {
        f.header = nlohmann::json::parse(h);
        Accumulation& a = f.acc;
        a.width = f.header.at("width").get<std::uint32_t>();
        a.height = f.header.at("height").get<std::uint32_t>();
        // The pixels held: files before windowed sums hold the whole image.
        const std::vector<std::uint32_t> w = f.header.value("window", std::vector<std::uint32_t>{0, a.width, 0, a.height});
        if (w.size() != 4 || w[0] >= w[1] || w[2] >= w[3] || w[1] > a.width || w[3] > a.height)
            throw InputError(fmt::format("{}: corrupted accumulation header: window {} of a {}x{} image", file.string(),
                                         f.header.at("window").dump(), a.width, a.height));
        a.window = {w[0], w[1], w[2], w[3]};
        a.nextChunk = f.header.at("next_chunk").get<std::uint64_t>();
        a.bandRows = f.header.value("band_rows", 0u);  // files before band-major sweeps: 0
        a.bandCols = f.header.value("band_cols", 0u);
        if (a.bandRows >= std::max(a.height, 1u) || a.bandCols >= std::max(a.width, 1u))
            throw InputError(fmt::format("{}: corrupted accumulation header: band at row {} column {} of {}x{}", file.string(),
                                         a.bandRows, a.bandCols, a.width, a.height));
    } catch (const nlohmann::json::exception& e) {
        throw InputError(fmt::format("{}: corrupted accumulation header: {}", file.string(), e.what()));
    }
    Accumulation& a = f.acc;
    const std::size_t px = a.pixels();
    std::uint64_t arrays = 0;
    if (__builtin_mul_overflow(std::uint64_t(px), std::uint64_t(6 * 8 + 4 + 1 + 4), &arrays) ||
        bytes.size() != r.position() + arrays + 8)
        throw InputError(fmt::format("{}: {} bytes do not hold {}x{} pixels", file.string(), bytes.size(), a.width, a.height));
    a.sum.resize(px);
    a.sumSq.resize(px);
    a.n.resize(px);
    a.done.resize(px);
    a.rejected.resize(px);
    r.get(a.sum.data(), px);
    r.get(a.sumSq.data(), px);
    r.get(a.n.data(), px);
    r.get(a.done.data(), px);
    r.get(a.rejected.data(), px);
    return f;
}

std::string settingsDifference(const nlohmann::json& header, const std::string& settings) {
    const std::string stored = header.value("settings", std::string());
    if (stored == settings) return {};
    std::istringstream a(stored), b(settings);
    std::string la, lb;
    std::string section;
    for (;;) {
        const bool ga = static_cast<bool>(std::getline(a, la));
        const bool gb = static_cast<bool>(std::getline(b, lb));
        if (!ga && !gb) return "settings differ";
        if (ga && gb && la == lb) {
            if (!la.empty() && la.front() == '[') section = la;
            continue;
        }
        return fmt::format("{} `{}` there, `{}` here", section, ga ? la : "(end)", gb ? lb : "(end)");
    }
}

}  // namespace accretion
