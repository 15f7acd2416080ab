#include "accretion/io/gpu_frame_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/read_file.h"

namespace accretion {
namespace {

constexpr char kMagic[8] = {'A', 'C', 'C', 'G', 'P', 'U', 'F', '1'};
constexpr std::uint64_t kMaxHeader = 1u << 26;

nlohmann::json vec(const DVec3& v) { return {v.x, v.y, v.z}; }
DVec3 dvec(const nlohmann::json& j) { return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()}; }

template <class T>
void append(std::string& out, const std::vector<T>& plane) {
    out.append(reinterpret_cast<const char*>(plane.data()), plane.size() * sizeof(T));
}

/// Every plane, each applied to `f` by `visit(name, plane)`, in the order
/// accretion writes them (a file's header lists its own order).
template <class Frame, class Visit>
void forEachPlane(Frame& f, Visit&& visit) {
    visit("L", f.L);
    visit("Le", f.Le);
    visit("Lr", f.Lr);
    visit("normal", f.normal);
    visit("depth", f.depth);
    visit("particle", f.particle);
    visit("Lr_stderr", f.Lr_stderr);
    visit("spp", f.spp);
    visit("rejected", f.rejected);
}

/// A camera as the renderer needs it: finite, an orthonormal basis, a field
/// of view, the jitter inside the pixel.
void checkCamera(const CameraPose& c, const std::string& name) {
    auto unit = [](const DVec3& v) { return std::fabs(glm::length(v) - 1.0) < 1e-4; };
    auto square = [](const DVec3& a, const DVec3& b) { return std::fabs(glm::dot(a, b)) < 1e-4; };
    const bool finite = std::isfinite(c.eye.x) && std::isfinite(c.eye.y) && std::isfinite(c.eye.z);
    if (!finite || !unit(c.forward) || !unit(c.right) || !unit(c.up) || !square(c.forward, c.right) ||
        !square(c.forward, c.up) || !square(c.right, c.up))
        throw InputError(fmt::format("{}: camera: eye must be finite and forward, right, up an orthonormal basis", name));
    if (!(c.tanHalfFov > 0.0 && c.tanHalfFov < 1e6))
        throw InputError(fmt::format("{}: camera: tan_half_fov {} is not a field of view", name, c.tanHalfFov));
    if (!(std::fabs(c.jitterX) <= 0.5 && std::fabs(c.jitterY) <= 0.5))
        throw InputError(fmt::format("{}: camera: jitter ({}, {}) px is outside the pixel ([-0.5, 0.5])", name, c.jitterX,
                                     c.jitterY));
}

}  // namespace

void writeGpuFrame(const std::filesystem::path& file, const GpuFrame& f) {
    const std::size_t n = std::size_t(f.width) * f.height;
    ACC_CHECK(f.Lr.size() == n);
    nlohmann::json planes = nlohmann::json::array();
    forEachPlane(f, [&](const char* name, const auto& plane) {
        ACC_CHECK(plane.empty() || plane.size() == n);
        if (!plane.empty()) planes.push_back(name);
    });
    const nlohmann::json header = {
        {"width", f.width}, {"height", f.height}, {"frame", f.frame},
        {"camera", {{"eye", vec(f.camera.eye)}, {"forward", vec(f.camera.forward)}, {"right", vec(f.camera.right)},
                    {"up", vec(f.camera.up)}, {"tan_half_fov", f.camera.tanHalfFov},
                    {"jitter", {f.camera.jitterX, f.camera.jitterY}}}},
        {"metadata", f.metadata},
        {"planes", planes},
    };
    const std::string text = header.dump();
    std::string bytes(kMagic, sizeof kMagic);
    const std::uint64_t len = text.size();
    bytes.append(reinterpret_cast<const char*>(&len), sizeof len);
    bytes += text;
    forEachPlane(f, [&](const char*, const auto& plane) { append(bytes, plane); });
    writeFileAtomic(file, bytes);
}

GpuFrame readGpuFrame(const std::filesystem::path& file) {
    const std::string name = file.string();
    std::ifstream in = openInputFile(file, "GPU frame");
    char magic[sizeof kMagic];
    std::uint64_t len = 0;
    if (!in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
        throw InputError(fmt::format("{}: not an accretion-optix frame (no ACCGPUF1 magic)", name));
    if (!in.read(reinterpret_cast<char*>(&len), sizeof len) || len > kMaxHeader)
        throw InputError(fmt::format("{}: bad header length", name));
    if (const std::uint64_t left = bytesLeft(in); len > left)
        throw InputError(fmt::format("{}: truncated header ({} bytes announced, the file holds {})", name, len, left));
    std::string text(len, '\0');
    if (!in.read(text.data(), std::streamsize(len))) throw InputError(fmt::format("{}: truncated header", name));
    GpuFrame f;
    std::vector<std::string> planes = {"L", "Le", "Lr", "normal", "depth", "particle"};  // files without "planes": the first six
    try {
        const nlohmann::json h = nlohmann::json::parse(text);
        f.width = h.at("width").get<std::uint32_t>();
        f.height = h.at("height").get<std::uint32_t>();
        const nlohmann::json& frame = h.at("frame");
        if (!frame.is_number_unsigned() || frame.get<std::uint64_t>() > 0xffffffffull)
            throw InputError(fmt::format("{}: header frame {}: expected a frame number from 0 to 4294967295", name, frame.dump()));
        f.frame = frame.get<std::uint32_t>();
        const auto& c = h.at("camera");
        f.camera.eye = dvec(c.at("eye"));
        f.camera.forward = dvec(c.at("forward"));
        f.camera.right = dvec(c.at("right"));
        f.camera.up = dvec(c.at("up"));
        f.camera.tanHalfFov = c.at("tan_half_fov").get<double>();
        f.camera.jitterX = c.at("jitter").at(0).get<double>();
        f.camera.jitterY = c.at("jitter").at(1).get<double>();
        f.metadata = h.at("metadata").get<std::map<std::string, std::string>>();
        if (h.contains("planes")) planes = h.at("planes").get<std::vector<std::string>>();
    } catch (const nlohmann::json::exception& e) {
        throw InputError(fmt::format("{}: bad header: {}", name, e.what()));
    }
    if (f.width == 0 || f.height == 0 || f.width > 16384 || f.height > 16384)
        throw InputError(fmt::format("{}: bad size {}x{}", name, f.width, f.height));
    checkCamera(f.camera, name);
    if (const auto m = f.metadata.find("frame"); m != f.metadata.end() && m->second != std::to_string(f.frame))
        throw InputError(fmt::format("{}: the header's frame {} disagrees with its metadata's frame {}", name, f.frame, m->second));
    const std::size_t n = std::size_t(f.width) * f.height;
    // The header's plane list: known names, each once, Lr among them.
    std::vector<std::string> known;
    forEachPlane(f, [&](const char* what, const auto&) { known.emplace_back(what); });
    for (std::size_t k = 0; k < planes.size(); ++k) {
        if (std::find(known.begin(), known.end(), planes[k]) == known.end() ||
            std::find(planes.begin(), planes.begin() + std::ptrdiff_t(k), planes[k]) != planes.begin() + std::ptrdiff_t(k))
            throw InputError(fmt::format("{}: bad plane list: '{}' is {} (known planes: {}; each once, Lr required)", name, planes[k],
                                         std::find(known.begin(), known.end(), planes[k]) == known.end() ? "no plane" : "listed twice",
                                         fmt::join(known, ", ")));
    }
    if (std::find(planes.begin(), planes.end(), "Lr") == planes.end())
        throw InputError(fmt::format("{}: bad plane list: no Lr (known planes: {}; each once, Lr required)", name, fmt::join(known, ", ")));
    // The planes' bytes, checked against the file before anything is allocated on the header's word.
    std::uint64_t need = 0;
    forEachPlane(f, [&](const char* what, const auto& plane) {
        if (std::find(planes.begin(), planes.end(), what) != planes.end()) need += n * sizeof(plane[0]);
    });
    if (const std::uint64_t have = bytesLeft(in); need != have)
        throw InputError(fmt::format("{}: the header's {}x{} planes ({}) take {} bytes, the file holds {}", name, f.width,
                                     f.height, fmt::join(planes, ", "), need, have));
    // In the order the header lists them: that is the file's order.
    for (const std::string& listed : planes)
        forEachPlane(f, [&](const char* what, auto& plane) {
            if (listed != what) return;
            plane.resize(n);
            if (!in.read(reinterpret_cast<char*>(plane.data()), std::streamsize(n * sizeof(plane[0]))))
                throw InputError(fmt::format("{}: truncated in plane {}", name, what));
        });
    return f;
}

}  // namespace accretion
