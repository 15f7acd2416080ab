#include "accretion/particles/particle_file.h"

#include <array>
#include <algorithm>
#include <bit>
#include <cctype>
#include <limits>
#include <optional>
#include <string_view>
#include <vector>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/core/atomic_file.h"
#include "accretion/core/parse.h"

namespace accretion {

static_assert(std::endian::native == std::endian::little, "particle files are little-endian; add byte swapping");

namespace {

constexpr std::array<const char*, 8> kFields = {"x", "y", "z", "radius", "emission_r", "emission_g", "emission_b", "opacity"};

/// Validate one record and store it.
void storeRecord(const std::string& file, std::size_t index, const float* f, Particles& out) {
    for (int k = 0; k < 8; ++k)
        if (!std::isfinite(f[k]))
            throw InputError(fmt::format("{}: record {}: {} is not finite ({})", file, index, kFields[k], f[k]));
    // Beyond 1e9 squared distances leave float range (the same bound as the scene's lengths).
    for (int k = 0; k < 3; ++k)
        if (std::fabs(f[k]) > 1e9f)
            throw InputError(fmt::format("{}: record {}: {} = {} is outside [-1e9, 1e9]", file, index, kFields[k], f[k]));
    if (!(f[3] > 0.0f) || f[3] > 1e9f)
        throw InputError(fmt::format("{}: record {}: radius must be > 0 and <= 1e9 (got {})", file, index, f[3]));
    for (int k = 4; k < 7; ++k)
        if (f[k] < 0.0f)
            throw InputError(fmt::format("{}: record {}: {} must be >= 0 (got {})", file, index, kFields[k], f[k]));
    if (f[7] < 0.0f || f[7] > 1.0f)
        throw InputError(fmt::format("{}: record {}: opacity must be in [0,1] (got {})", file, index, f[7]));
    out.position[index] = Vec3(f[0], f[1], f[2]);
    out.radius[index] = f[3];
    out.emission[index] = Vec3(f[4], f[5], f[6]);
    out.opacity[index] = f[7];
}

/// The first `limit` bytes of a file (all of it when smaller) and its size.
std::string readHead(const std::filesystem::path& file, std::size_t limit, std::uint64_t& size) {
    std::ifstream in = openInputFile(file, "particle file");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec))
        throw InputError(fmt::format("{}: not a regular file", file.string()));
    size = std::filesystem::file_size(file, ec);
    if (ec) throw InputError(fmt::format("{}: cannot read its size: {}", file.string(), ec.message()));
    std::string bytes(std::size_t(std::min<std::uint64_t>(size, limit)), '\0');
    in.read(bytes.data(), std::streamsize(bytes.size()));
    if (std::size_t(in.gcount()) != bytes.size()) throw InputError(fmt::format("{}: read error", file.string()));
    return bytes;
}

/// A PLY header holds at most this many bytes (a particle file's header is
/// a few hundred): a file without `end_header` in them is refused.
constexpr std::size_t kMaxPlyHeader = 64 * 1024;

bool hasPlyMagic(std::string_view bytes) {
    return bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n";
}

bool hasPlyExtension(const std::filesystem::path& file) {
    std::string ext = file.extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".ply";
}

/// How a vertex property is converted: the types accretion reads.
enum class PlyType { float32, float64, uint8, other };

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::other;
    std::string typeName;
    std::size_t offset = 0;  ///< within a vertex record
    std::size_t line = 0;
};

/// A binary PLY file's layout: where the vertex records are and how to read
/// their properties; the body's size is checked against the header exactly.
struct PlyLayout {
    std::size_t count = 0;        ///< vertices
    std::size_t stride = 0;       ///< bytes per vertex
    std::size_t vertexStart = 0;  ///< offset of the first vertex in the file
    std::array<std::optional<PlyProperty>, 8> fields{};  ///< kFields as declared; empty when absent (opacity only)
    std::vector<PlyProperty> properties;
};

std::size_t plyTypeSize(std::string_view t, PlyType& kind) {
    kind = PlyType::other;
    if (t == "float" || t == "float32") { kind = PlyType::float32; return 4; }
    if (t == "double" || t == "float64") { kind = PlyType::float64; return 8; }
    if (t == "uchar" || t == "uint8") { kind = PlyType::uint8; return 1; }
    if (t == "char" || t == "int8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "int32" || t == "uint32") return 4;
    return 0;
}

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> w;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t b = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > b) w.push_back(line.substr(b, i - b));
    }
    return w;
}

/// An element of a PLY header: its records' count and bytes.
struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::uint64_t stride = 0;
    std::size_t line = 0;
};

/// What the header's lines declare.
struct PlyHeaderLines {
    std::vector<PlyElement> elements;
    std::size_t vertexElement = ~std::size_t(0);
    std::vector<PlyProperty> vertexProperties;
    std::uint64_t headerBytes = 0;  ///< up to and with the end_header line
};

/// The header's lines, LF or CRLF, checked one by one.
PlyHeaderLines readPlyHeaderLines(const std::string& name, std::string_view head) {
    PlyHeaderLines h;
    std::vector<PlyElement>& elements = h.elements;
    std::size_t pos = 0, lineNo = 0;
    bool sawFormat = false, ended = false;
    while (!ended) {
        const std::size_t nl = head.find('\n', pos);
        if (nl == std::string_view::npos)
            throw InputError(fmt::format("{}: PLY header has no 'end_header' line in its first {} KiB", name,
                                         kMaxPlyHeader / 1024));
        std::string_view line = head.substr(pos, nl - pos);
        pos = nl + 1;
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::vector<std::string_view> w = words(line);
        auto fail = [&](const std::string& msg) -> void { throw InputError(fmt::format("{}:{}: {}", name, lineNo, msg)); };
        if (lineNo == 1) continue;  // the magic, already checked
        if (w.empty()) fail("empty PLY header line");
        if (w[0] == "comment" || w[0] == "obj_info") continue;  // free text, whatever it says
        if (w[0] == "end_header") {
            if (w.size() != 1) fail(fmt::format("unexpected words after end_header: '{}'", line));
            ended = true;
        } else if (w[0] == "format") {
            if (w.size() != 3) fail(fmt::format("expected 'format binary_little_endian 1.0', got '{}'", line));
            if (w[1] != "binary_little_endian")
                fail(fmt::format("PLY format '{}' not supported (binary_little_endian only)", w[1]));
            if (w[2] != "1.0") fail(fmt::format("PLY version '{}' not supported (1.0)", w[2]));
            if (sawFormat) fail("a second format line");
            sawFormat = true;
        } else if (w[0] == "element") {
            if (w.size() != 3) fail(fmt::format("expected 'element NAME COUNT', got '{}'", line));
            const std::optional<std::uint64_t> n = parseUnsigned(w[2]);
            if (!n) fail(fmt::format("element {}: count '{}' is not a non-negative integer", w[1], w[2]));
            for (const PlyElement& e : elements)
                if (e.name == w[1]) fail(fmt::format("element {} declared twice (first at line {})", w[1], e.line));
            if (w[1] == "vertex") h.vertexElement = elements.size();
            elements.push_back({std::string(w[1]), *n, 0, lineNo});
        } else if (w[0] == "property") {
            if (elements.empty()) fail("property before any element");
            PlyElement& e = elements.back();
            if (w.size() >= 2 && w[1] == "list")
                fail(fmt::format("element {}: list properties are not supported (the body size could not be checked)", e.name));
            if (w.size() == 2) fail(fmt::format("element {}: property without a name", e.name));
            if (w.size() != 3) fail(fmt::format("expected 'property TYPE NAME', got '{}'", line));
            PlyType kind;
            const std::size_t size = plyTypeSize(w[1], kind);
            if (!size) fail(fmt::format("unknown property type '{}'", w[1]));
            if (elements.size() - 1 == h.vertexElement) {
                for (const PlyProperty& q : h.vertexProperties)
                    if (q.name == w[2]) fail(fmt::format("vertex property '{}' declared twice (first at line {})", w[2], q.line));
                h.vertexProperties.push_back({std::string(w[2]), kind, std::string(w[1]), std::size_t(e.stride), lineNo});
            }
            e.stride += size;
        } else {
            fail(fmt::format("unexpected PLY header line '{}'", line));
        }
    }
    if (!sawFormat) throw InputError(fmt::format("{}: PLY header has no format line", name));
    if (h.vertexElement == ~std::size_t(0)) throw InputError(fmt::format("{}: PLY header has no vertex element", name));
    h.headerBytes = pos;
    return h;
}

/// The vertex properties accretion reads, by field, each of a type it reads.
void pickPlyFields(const std::string& name, PlyLayout& layout) {
    for (const PlyProperty& q : layout.properties)
        for (std::size_t k = 0; k < kFields.size(); ++k)
            if (q.name == kFields[k]) {
                const bool ok = q.type == PlyType::float32 || q.type == PlyType::float64 ||
                                (k == 7 && q.type == PlyType::uint8);
                if (!ok)
                    throw InputError(fmt::format("{}:{}: vertex property '{}' is {}: accretion reads float, float32, double, "
                                                 "float64{}", name, q.line, q.name, q.typeName,
                                                 k == 7 ? ", and uchar/uint8 (0..255 = 0..1)" : ""));
                layout.fields[k] = q;
            }
    for (int k = 0; k < 7; ++k)
        if (!layout.fields[k])
            throw InputError(fmt::format("{}: PLY vertex has no property '{}' (float or double)", name, kFields[k]));
}

/// Parse the header line by line (LF or CRLF); `fileSize` is the whole file's.
PlyLayout parsePlyHeader(const std::string& name, std::string_view head, std::uint64_t fileSize) {
    const PlyHeaderLines h = readPlyHeaderLines(name, head);
    PlyLayout layout;
    layout.properties = h.vertexProperties;
    // The body: every element's records, in order, exactly.
    const std::uint64_t headerBytes = h.headerBytes;
    std::uint64_t body = 0, vertexStart = headerBytes;
    for (std::size_t k = 0; k < h.elements.size(); ++k) {
        const PlyElement& e = h.elements[k];
        std::uint64_t bytes = 0;
        if (__builtin_mul_overflow(e.count, e.stride, &bytes) || __builtin_add_overflow(body, bytes, &body))
            throw InputError(fmt::format("{}:{}: element {}: {} records of {} bytes cannot be a file", name, e.line, e.name,
                                         e.count, e.stride));
        if (k < h.vertexElement) vertexStart += bytes;
    }
    pickPlyFields(name, layout);
    const PlyElement& v = h.elements[h.vertexElement];
    if (fileSize - headerBytes != body) {
        const std::uint64_t have = fileSize - headerBytes;
        const std::uint64_t before = vertexStart - headerBytes;
        if (have < body)
            throw InputError(fmt::format("{}: truncated: header declares {} vertices, the body ends in record {} ({} of {} "
                                         "bytes)", name, v.count, have > before && v.stride ? (have - before) / v.stride : 0,
                                         have, body));
        throw InputError(fmt::format("{}: {} bytes after the {} declared vertices: the header's count does not match the body",
                                     name, have - body, v.count));
    }
    if (v.count == 0) throw InputError(fmt::format("{}: no particles (vertex count 0)", name));
    layout.count = std::size_t(v.count);
    layout.stride = std::size_t(v.stride);
    layout.vertexStart = std::size_t(vertexStart);
    return layout;
}

float plyValue(const char* record, const PlyProperty& q) {
    switch (q.type) {
    case PlyType::float32: {
        float f;
        std::memcpy(&f, record + q.offset, 4);
        return f;
    }
    case PlyType::float64: {
        double d;
        std::memcpy(&d, record + q.offset, 8);
        return float(d);
    }
    case PlyType::uint8: return float(static_cast<unsigned char>(record[q.offset])) / 255.0f;
    case PlyType::other: break;
    }
    ACC_CHECK(false);
    return 0.0f;
}

Particles readPly(const std::string& name, std::string_view bytes) {
    const PlyLayout layout = parsePlyHeader(name, bytes.substr(0, kMaxPlyHeader), bytes.size());
    Particles out;
    out.resize(layout.count);
    for (std::size_t i = 0; i < layout.count; ++i) {
        const char* rec = bytes.data() + layout.vertexStart + i * layout.stride;
        float f[8];
        for (int k = 0; k < 8; ++k) f[k] = layout.fields[k] ? plyValue(rec, *layout.fields[k]) : 1.0f;
        storeRecord(name, i, f, out);
    }
    return out;
}

Particles readRaw(const std::string& name, std::string_view bytes) {
    if (bytes.size() % kParticleRecordBytes != 0)
        throw InputError(fmt::format("{}: size {} bytes is not a multiple of {} (record {} is truncated)", name,
                                     bytes.size(), kParticleRecordBytes, bytes.size() / kParticleRecordBytes));
    const std::size_t n = bytes.size() / kParticleRecordBytes;
    if (n == 0) throw InputError(fmt::format("{}: no particles (empty file)", name));
    Particles out;
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        float f[8];
        std::memcpy(f, bytes.data() + i * kParticleRecordBytes, sizeof f);
        storeRecord(name, i, f, out);
    }
    return out;
}

ParticleFormat formatOf(const std::string& name, const std::filesystem::path& file, std::string_view head) {
    if (hasPlyMagic(head)) return ParticleFormat::ply;
    if (hasPlyExtension(file))
        throw InputError(fmt::format("{}: not a PLY file (it does not start with the line 'ply')", name));
    return ParticleFormat::raw;
}

}  // namespace

Particles parseParticles(const std::filesystem::path& file, std::string_view bytes) {
    const std::string name = file.string();
    return formatOf(name, file, bytes) == ParticleFormat::ply ? readPly(name, bytes) : readRaw(name, bytes);
}

Particles readParticles(const std::filesystem::path& file) {
    std::uint64_t size = 0;
    const std::string bytes = readHead(file, std::numeric_limits<std::size_t>::max(), size);
    return parseParticles(file, bytes);
}

ParticleFileInfo inspectParticleFile(const std::filesystem::path& file) {
    const std::string name = file.string();
    std::uint64_t size = 0;
    const std::string head = readHead(file, kMaxPlyHeader, size);
    ParticleFileInfo info{formatOf(name, file, head), 0};
    if (info.format == ParticleFormat::ply) {
        info.count = parsePlyHeader(name, head, size).count;
    } else {
        if (size % kParticleRecordBytes != 0)
            throw InputError(fmt::format("{}: size {} bytes is not a multiple of {} (record {} is truncated)", name, size,
                                         kParticleRecordBytes, size / kParticleRecordBytes));
        if (size == 0) throw InputError(fmt::format("{}: no particles (empty file)", name));
        info.count = std::size_t(size / kParticleRecordBytes);
    }
    return info;
}

void writeParticles(const std::filesystem::path& file, const Particles& p, ParticleFormat format) {
    std::string bytes;
    if (format == ParticleFormat::ply) {
        bytes = fmt::format("ply\nformat binary_little_endian 1.0\ncomment accretion particles\nelement vertex {}\n", p.size());
        for (const char* f : kFields) bytes += fmt::format("property float {}\n", f);
        bytes += "end_header\n";
    }
    const std::size_t start = bytes.size();
    bytes.resize(start + p.size() * kParticleRecordBytes);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const float f[8] = {p.position[i].x, p.position[i].y, p.position[i].z, p.radius[i],
                            p.emission[i].x, p.emission[i].y, p.emission[i].z, p.opacity[i]};
        std::memcpy(bytes.data() + start + i * kParticleRecordBytes, f, sizeof f);
    }
    writeFileAtomic(file, bytes);
}

}  // namespace accretion
