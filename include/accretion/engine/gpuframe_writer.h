// gpuframe_writer.h: a reference writer of accretion's .gpuframe format
// (docs/gpu-frame-format.md) for a GPU engine. Standalone on purpose: it needs
// only the C++17 standard library, so an engine copies this one file and
// writes its frames for `accretion import-gpu` and `accretion bias
// --gpu-frames`. tests/io/gpuframe_writer_test.cpp reads what it writes back
// with accretion's own reader, plane for plane, bit for bit.
#pragma once
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace accretion_engine {

/// One frame as the engine read it back from the GPU. Planes are
/// width x height, row-major from the top row, little-endian; float3 planes
/// are 3 floats per pixel. Lr is required; a plane left empty is not written
/// (import-gpu needs L, Le, Lr, normal, depth, particle; bias needs Lr).
struct GpuFrameOut {
    std::uint32_t width = 0, height = 0, frame = 0;
    /// The camera: eye (world), and the unit basis the primary rays use:
    /// a pixel's ray goes through forward + (2 (x + 0.5 + jitter_x) / W - 1)
    /// tan_half_fov (W / H) right + (1 - 2 (y + 0.5 + jitter_y) / H)
    /// tan_half_fov up; jitter in pixels, +x right, +y down, within [-0.5, 0.5].
    double eye[3] = {0, 0, 0}, forward[3] = {0, 0, -1}, right[3] = {1, 0, 0}, up[3] = {0, 1, 0};
    double tanHalfFov = 0.41421356237309503, jitter[2] = {0, 0};
    /// What made the frame, as accretion's EXR attributes name it (no
    /// accretion: prefix): "frame" (must equal `frame` when given), "seed" and
    /// "estimator" (bias checks them), "settings" (the scene TOML: bias checks
    /// its scene sections against the reference), "device", "render_time_s".
    std::map<std::string, std::string> metadata;
    std::vector<float> L, Le, Lr, normal;   ///< float3 planes: 3 * width * height floats
    std::vector<float> depth;               ///< width * height
    std::vector<std::uint32_t> particle;    ///< 0xffffffff where the ray missed
    std::vector<float> Lr_stderr;           ///< float3 (Monte Carlo estimators)
    std::vector<float> spp, rejected;       ///< width * height
};

namespace detail {

inline std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') out += '\\', out += c;
        else if (c == '\n') out += "\\n";
        else if (c == '\t') out += "\\t";
        else if (static_cast<unsigned char>(c) < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out += buf;
        } else out += c;
    }
    return out + "\"";
}

/// The shortest text that reads back as `v`, whatever the process's locale
/// (printf's "%g" writes "0,5" under a decimal-comma LC_NUMERIC, which is
/// not JSON). Non-finite values have no JSON form: the caller refuses them.
inline std::string jsonNumber(double v) {
    char buf[32];
    const std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

inline bool finite(const double* v, int n) {
    for (int k = 0; k < n; ++k)
        if (!std::isfinite(v[k])) return false;
    return true;
}

inline std::string jsonVec(const double* v, int n) {
    std::string out = "[";
    for (int k = 0; k < n; ++k) out += (k ? "," : "") + jsonNumber(v[k]);
    return out + "]";
}

}  // namespace detail

/// Writes `f` to `path` through `path`.tmp and a rename, so a reader never
/// sees half a frame. Returns false when a plane has the wrong size, Lr is
/// missing, the camera is not finite, or the file cannot be written (errno
/// set). Little-endian hosts. The header is the same under any locale.
inline bool writeGpuFrame(const std::string& path, const GpuFrameOut& f) {
    const std::size_t n = std::size_t(f.width) * f.height;
    struct Plane { const char* name; const void* data; std::size_t bytes, expected; };
    const Plane planes[] = {
        {"L", f.L.data(), f.L.size() * 4, 3 * n * 4},           {"Le", f.Le.data(), f.Le.size() * 4, 3 * n * 4},
        {"Lr", f.Lr.data(), f.Lr.size() * 4, 3 * n * 4},        {"normal", f.normal.data(), f.normal.size() * 4, 3 * n * 4},
        {"depth", f.depth.data(), f.depth.size() * 4, n * 4},   {"particle", f.particle.data(), f.particle.size() * 4, n * 4},
        {"Lr_stderr", f.Lr_stderr.data(), f.Lr_stderr.size() * 4, 3 * n * 4},
        {"spp", f.spp.data(), f.spp.size() * 4, n * 4},         {"rejected", f.rejected.data(), f.rejected.size() * 4, n * 4}};
    if (n == 0 || f.Lr.empty()) return false;
    if (!detail::finite(f.eye, 3) || !detail::finite(f.forward, 3) || !detail::finite(f.right, 3) || !detail::finite(f.up, 3) ||
        !detail::finite(&f.tanHalfFov, 1) || !detail::finite(f.jitter, 2))
        return false;
    std::string names;
    for (const Plane& p : planes) {
        if (p.bytes == 0) continue;
        if (p.bytes != p.expected) return false;
        names += (names.empty() ? "" : ",") + detail::jsonString(p.name);
    }
    std::string meta;
    for (const auto& [k, v] : f.metadata) meta += (meta.empty() ? "" : ",") + detail::jsonString(k) + ":" + detail::jsonString(v);
    const std::string header =
        "{\"width\":" + std::to_string(f.width) + ",\"height\":" + std::to_string(f.height) +
        ",\"frame\":" + std::to_string(f.frame) + ",\"camera\":{\"eye\":" + detail::jsonVec(f.eye, 3) +
        ",\"forward\":" + detail::jsonVec(f.forward, 3) + ",\"right\":" + detail::jsonVec(f.right, 3) +
        ",\"up\":" + detail::jsonVec(f.up, 3) + ",\"tan_half_fov\":" + detail::jsonNumber(f.tanHalfFov) +
        ",\"jitter\":" + detail::jsonVec(f.jitter, 2) + "},\"metadata\":{" + meta + "},\"planes\":[" + names + "]}";
    const std::string tmp = path + ".tmp";
    std::FILE* out = std::fopen(tmp.c_str(), "wb");
    if (!out) return false;
    const std::uint64_t length = header.size();
    bool ok = std::fwrite("ACCGPUF1", 1, 8, out) == 8 && std::fwrite(&length, 8, 1, out) == 1 &&
              std::fwrite(header.data(), 1, header.size(), out) == header.size();
    for (const Plane& p : planes)
        if (ok && p.bytes) ok = std::fwrite(p.data, 1, p.bytes, out) == p.bytes;
    ok = std::fclose(out) == 0 && ok;
    if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        return false;
    }
    return true;
}

}  // namespace accretion_engine
