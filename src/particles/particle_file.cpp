#include "accretion/particles/particle_file.h"

#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/atomic_file.h"

namespace accretion {

static_assert(std::endian::native == std::endian::little, "particle files are little-endian; add byte swapping");

namespace {

constexpr std::array<const char*, 8> kFields = {"x", "y", "z", "radius", "emission_r", "emission_g", "emission_b", "opacity"};

/// Validate one record and store it.
void storeRecord(const std::filesystem::path& file, std::size_t index, const float* f, Particles& out) {
    for (int k = 0; k < 8; ++k)
        if (!std::isfinite(f[k]))
            throw InputError(fmt::format("{}: record {}: {} is not finite ({})", file.string(), index, kFields[k], f[k]));
    // Beyond 1e9 squared distances leave float range (the same bound as the scene's lengths).
    for (int k = 0; k < 3; ++k)
        if (std::fabs(f[k]) > 1e9f)
            throw InputError(fmt::format("{}: record {}: {} = {} is outside [-1e9, 1e9]", file.string(), index, kFields[k], f[k]));
    if (!(f[3] > 0.0f) || f[3] > 1e9f)
        throw InputError(fmt::format("{}: record {}: radius must be > 0 and <= 1e9 (got {})", file.string(), index, f[3]));
    for (int k = 4; k < 7; ++k)
        if (f[k] < 0.0f)
            throw InputError(fmt::format("{}: record {}: {} must be >= 0 (got {})", file.string(), index, kFields[k], f[k]));
    if (f[7] < 0.0f || f[7] > 1.0f)
        throw InputError(fmt::format("{}: record {}: opacity must be in [0,1] (got {})", file.string(), index, f[7]));
    out.position[index] = Vec3(f[0], f[1], f[2]);
    out.radius[index] = f[3];
    out.emission[index] = Vec3(f[4], f[5], f[6]);
    out.opacity[index] = f[7];
}

std::string readAll(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(fmt::format("{}: cannot open particle file", file.string()));
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(fmt::format("{}: read error", file.string()));
    return bytes;
}

Particles readRaw(const std::filesystem::path& file, const std::string& bytes) {
    if (bytes.size() % kParticleRecordBytes != 0)
        throw InputError(fmt::format("{}: size {} bytes is not a multiple of {} (record {} is truncated)", file.string(),
                                     bytes.size(), kParticleRecordBytes, bytes.size() / kParticleRecordBytes));
    const std::size_t n = bytes.size() / kParticleRecordBytes;
    if (n == 0) throw InputError(fmt::format("{}: no particles (empty file)", file.string()));
    Particles out;
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        float f[8];
        std::memcpy(f, bytes.data() + i * kParticleRecordBytes, sizeof f);
        storeRecord(file, i, f, out);
    }
    return out;
}

std::size_t plyTypeSize(const std::string& t) {
    static const std::map<std::string, std::size_t> sizes = {
        {"char", 1}, {"uchar", 1}, {"int8", 1}, {"uint8", 1}, {"short", 2}, {"ushort", 2}, {"int16", 2},
        {"uint16", 2}, {"int", 4}, {"uint", 4}, {"int32", 4}, {"uint32", 4}, {"float", 4}, {"float32", 4},
        {"double", 8}, {"float64", 8}};
    auto it = sizes.find(t);
    return it == sizes.end() ? 0 : it->second;
}

Particles readPly(const std::filesystem::path& file, const std::string& bytes) {
    const std::string name = file.string();
    const auto headerEnd = bytes.find("end_header\n");
    if (bytes.rfind("ply\n", 0) != 0 || headerEnd == std::string::npos)
        throw InputError(fmt::format("{}: not a PLY file (missing 'ply' magic or 'end_header')", name));
    std::istringstream header(bytes.substr(0, headerEnd));
    std::string line;
    std::size_t count = 0, stride = 0, lineNo = 0;
    bool inVertex = false, sawVertex = false, sawFormat = false;
    std::map<std::string, std::size_t> offsets;  // float properties of the vertex element
    while (std::getline(header, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream words(line);
        std::string w;
        words >> w;
        if (w == "format") {
            std::string fmtName;
            words >> fmtName;
            if (fmtName != "binary_little_endian")
                throw InputError(fmt::format("{}:{}: PLY format '{}' not supported (binary_little_endian only)", name, lineNo, fmtName));
            sawFormat = true;
        } else if (w == "element") {
            std::string elem;
            long long n = -1;
            words >> elem >> n;
            if (sawVertex && !inVertex) continue;
            inVertex = elem == "vertex";
            if (inVertex) {
                if (n < 0) throw InputError(fmt::format("{}:{}: bad vertex count", name, lineNo));
                if (sawVertex) throw InputError(fmt::format("{}:{}: two vertex elements", name, lineNo));
                if (stride || offsets.size()) throw InputError(fmt::format("{}:{}: vertex must be the first element", name, lineNo));
                count = static_cast<std::size_t>(n);
                sawVertex = true;
            } else if (!sawVertex) {
                throw InputError(fmt::format("{}:{}: vertex must be the first element", name, lineNo));
            }
        } else if (w == "property" && inVertex) {
            std::string type, prop;
            words >> type >> prop;
            if (type == "list") throw InputError(fmt::format("{}:{}: list properties not supported in vertex", name, lineNo));
            const std::size_t size = plyTypeSize(type);
            if (!size) throw InputError(fmt::format("{}:{}: unknown property type '{}'", name, lineNo, type));
            if (size == 4 && (type == "float" || type == "float32")) offsets[prop] = stride;
            stride += size;
        } else if (w != "ply" && w != "comment" && w != "obj_info" && w != "property" && !w.empty()) {
            throw InputError(fmt::format("{}:{}: unexpected PLY header line '{}'", name, lineNo, line));
        }
    }
    if (!sawFormat) throw InputError(fmt::format("{}: PLY header has no format line", name));
    if (!sawVertex) throw InputError(fmt::format("{}: PLY header has no vertex element", name));
    for (int k = 0; k < 7; ++k)
        if (!offsets.count(kFields[k]))
            throw InputError(fmt::format("{}: PLY vertex has no float property '{}'", name, kFields[k]));
    if (count == 0) throw InputError(fmt::format("{}: no particles (vertex count 0)", name));
    const std::size_t dataStart = headerEnd + std::strlen("end_header\n");
    const std::size_t available = bytes.size() - dataStart;
    if (available < count * stride)
        throw InputError(fmt::format("{}: truncated: header declares {} records, data ends in record {}", name, count,
                                     available / stride));
    Particles out;
    out.resize(count);
    const bool hasOpacity = offsets.count("opacity") > 0;
    for (std::size_t i = 0; i < count; ++i) {
        const char* rec = bytes.data() + dataStart + i * stride;
        float f[8];
        for (int k = 0; k < 7; ++k) std::memcpy(&f[k], rec + offsets[kFields[k]], 4);
        f[7] = 1.0f;
        if (hasOpacity) std::memcpy(&f[7], rec + offsets["opacity"], 4);
        storeRecord(file, i, f, out);
    }
    return out;
}

}  // namespace

ParticleFormat particleFormatOf(const std::filesystem::path& file) {
    return file.extension() == ".ply" ? ParticleFormat::ply : ParticleFormat::raw;
}

Particles readParticles(const std::filesystem::path& file) {
    const std::string bytes = readAll(file);
    return particleFormatOf(file) == ParticleFormat::ply ? readPly(file, bytes) : readRaw(file, bytes);
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
