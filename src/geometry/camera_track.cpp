#include "accretion/geometry/camera_track.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <type_traits>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/json_text.h"
#include "accretion/core/read_file.h"

namespace accretion {
namespace {

using Convention = CameraConvention;

Mat4 transpose(const Mat4& m) {
    Mat4 t{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) t[r][c] = m[c][r];
    return t;
}

/// The 16 numbers of a file as the matrix acting on column vectors.
Mat4 fromStored(const std::array<double, 16>& v, const Convention& conv) {
    Mat4 a{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) a[r][c] = conv.storage == Convention::Storage::row_major ? v[4 * r + c] : v[4 * c + r];
    return conv.vectors == Convention::Vectors::row ? transpose(a) : a;
}

std::array<double, 16> toStored(const Mat4& m, const Convention& conv) {
    const Mat4 a = conv.vectors == Convention::Vectors::row ? transpose(m) : m;
    std::array<double, 16> v{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) (conv.storage == Convention::Storage::row_major ? v[4 * r + c] : v[4 * c + r]) = a[r][c];
    return v;
}

double sign(double x) { return x < 0.0 ? -1.0 : 1.0; }

/// The sign NDC y has on the image's upward axis.
double clipUp(const Convention& c) { return c.clip == Convention::Clip::vulkan ? -1.0 : 1.0; }

/// The sign of w = P[3][2] z: view space looks down -z (right-handed) or +z.
double viewDepth(const Convention& c) { return c.handedness == Convention::Handedness::right ? -1.0 : 1.0; }

/// A reciprocal that round-trips: 1 / result == t exactly (when some double
/// within a few ulps has that property, as all tested ones do).
double exactReciprocal(double t) {
    double r = 1.0 / t;
    for (int k = 0; k < 8 && 1.0 / r != t; ++k) r = std::nextafter(r, 1.0 / r < t ? 0.0 : 2.0 * r);
    return r;
}

}  // namespace

bool CameraConvention::preset(const std::string& name, CameraConvention& out) {
    out = CameraConvention{};
    if (name == "opengl") return true;
    if (name == "vulkan") {
        out.clip = Clip::vulkan;
        return true;
    }
    if (name == "d3d") {
        out.storage = Storage::row_major;
        out.vectors = Vectors::row;
        out.handedness = Handedness::left;
        out.clip = Clip::d3d;
        return true;
    }
    return false;
}

CameraPose poseFromMatrices(const Mat4& V, const Mat4& P, const CameraConvention& conv, std::uint32_t width,
                            std::uint32_t height, const std::string& where) {
    // The view: rows 0..2 of its rotation are the view axes in world space.
    DVec3 axis[3];
    for (int r = 0; r < 3; ++r) axis[r] = DVec3(V[r][0], V[r][1], V[r][2]);
    for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) {
            const double d = glm::dot(axis[r], axis[c]);
            if (std::fabs(d - (r == c ? 1.0 : 0.0)) > 1e-5)
                throw InputError(fmt::format("{}: the view matrix is not a rigid transform (rows {} and {} of its rotation: "
                                             "dot {:.6g}); check the convention's storage and vectors", where, r, c, d));
        }
    if (V[3][0] != 0.0 || V[3][1] != 0.0 || V[3][2] != 0.0 || V[3][3] != 1.0)
        throw InputError(fmt::format("{}: the view matrix's last row is not (0, 0, 0, 1); check the convention's storage "
                                     "and vectors", where));
    // The projection: a perspective one, w = +-z.
    const double w = P[3][2];
    if (std::fabs(std::fabs(w) - 1.0) > 1e-9 || P[3][0] != 0.0 || P[3][1] != 0.0 || P[3][3] != 0.0)
        throw InputError(fmt::format("{}: the projection is not a perspective one (its last row must be (0, 0, +-1, 0))", where));
    if (sign(w) != viewDepth(conv))
        throw InputError(fmt::format("{}: the projection divides by {}z, but the convention is {}-handed (view space looks "
                                     "down {}z)", where, w > 0 ? "+" : "-",
                                     conv.handedness == Convention::Handedness::right ? "right" : "left",
                                     conv.handedness == Convention::Handedness::right ? "-" : "+"));
    if (!(P[0][0] != 0.0 && P[1][1] != 0.0 && std::isfinite(P[0][0]) && std::isfinite(P[1][1])))
        throw InputError(fmt::format("{}: the projection has no finite field of view", where));
    const double aspect = std::fabs(P[1][1] / P[0][0]), imageAspect = double(width) / double(height);
    if (std::fabs(aspect / imageAspect - 1.0) > 1e-4)
        throw InputError(fmt::format("{}: the projection's aspect ratio is {:.6g}, the image's {}x{} is {:.6g}", where, aspect,
                                     width, height, imageAspect));
    CameraPose pose;
    pose.right = axis[0] * sign(P[0][0]);
    pose.up = axis[1] * (sign(P[1][1]) * clipUp(conv));
    pose.forward = axis[2] * viewDepth(conv);  // view -z (right-handed) or +z is forward
    pose.tanHalfFov = 1.0 / std::fabs(P[1][1]);
    // eye = -R^T t
    const DVec3 t(V[0][3], V[1][3], V[2][3]);
    pose.eye = -(axis[0] * t.x + axis[1] * t.y + axis[2] * t.z);
    // Off-centre terms: the image shifted by (ox, oy) in NDC, so the samples
    // are offset the other way (NDC x is right everywhere; y up but in vulkan).
    const double ox = P[0][2] * w, oy = P[1][2] * w;
    pose.jitterX = -ox * 0.5 * double(width);
    pose.jitterY = oy * clipUp(conv) * 0.5 * double(height);
    return pose;
}

void matricesFromPose(const CameraPose& pose, const CameraConvention& conv, std::uint32_t width, std::uint32_t height,
                      Mat4& V, Mat4& P) {
    const DVec3 z = conv.handedness == Convention::Handedness::right ? -pose.forward : pose.forward;
    const DVec3 up = pose.up * clipUp(conv);
    const DVec3 axis[3] = {pose.right, up, z};
    V = Mat4{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) V[r][c] = axis[r][c];
        V[r][3] = -glm::dot(axis[r], pose.eye);
    }
    V[3][3] = 1.0;
    P = Mat4{};
    const double w = viewDepth(conv);
    P[1][1] = exactReciprocal(pose.tanHalfFov);
    P[0][0] = P[1][1] * double(height) / double(width);
    P[0][2] = -pose.jitterX / (0.5 * double(width)) * w;
    P[1][2] = pose.jitterY * clipUp(conv) / (0.5 * double(height)) * w;
    // Depth to [0, 1] (d3d, vulkan) or [-1, 1] (opengl) between 0.01 and 1e4: not used by accretion.
    const double n = 0.01, f = 1e4;
    const bool zeroToOne = conv.clip != Convention::Clip::opengl;
    P[2][2] = w * (zeroToOne ? f / (f - n) : (f + n) / (f - n));
    P[2][3] = zeroToOne ? -f * n / (f - n) : -2.0 * f * n / (f - n);
    P[3][2] = w;
}

namespace {

/// One frame's record of a camera file, whatever its format.
struct CameraRecord {
    std::uint32_t frame = 0;
    bool matrices = false;
    DVec3 eye{0.0}, lookAt{0.0}, up{0.0, 1.0, 0.0};
    double fov = 45.0;
    std::array<double, 16> view{}, projection{};
    bool hasJitter = false;
    double jitter[2] = {0.0, 0.0};
};

struct CameraFileContent {
    CameraConvention convention;
    bool ndcJitter = false;
    std::vector<std::pair<std::string, CameraRecord>> records;  ///< where (file:line or file: frames[i]), record
};

/// `out` = the value named `v` among `options`, else InputError listing them.
template <class E>
void pickValue(E& out, const std::string& v, std::initializer_list<std::pair<const char*, std::type_identity_t<E>>> options,
               const std::string& where, const std::string& key) {
    std::vector<std::string> names;
    for (const auto& [name, value] : options) {
        if (v == name) {
            out = value;
            return;
        }
        names.emplace_back(name);
    }
    throw InputError(fmt::format("{}: convention.{} \"{}\": expected one of {}", where, key, v, fmt::join(names, ", ")));
}

/// jitter_units: "pixels" or "ndc", in any case (a CSV's "# jitter_units = NDC").
bool jitterInNdc(const std::string& value, const std::string& where) {
    std::string units = value;
    std::transform(units.begin(), units.end(), units.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (units != "pixels" && units != "ndc")
        throw InputError(fmt::format("{}: jitter_units \"{}\": expected pixels or ndc", where, value));
    return units == "ndc";
}

CameraConvention parseConvention(const nlohmann::json& j, const std::string& where) {
    CameraConvention c;
    if (j.is_string()) {
        if (!CameraConvention::preset(j.get<std::string>(), c))
            throw InputError(fmt::format("{}: convention \"{}\": expected opengl, vulkan, d3d or an object", where,
                                         j.get<std::string>()));
        return c;
    }
    if (!j.is_object()) throw InputError(fmt::format("{}: convention: expected a preset name or an object", where));
    for (const auto& item : j.items()) {
        const std::string key = item.key();
        const std::string v = item.value().is_string() ? item.value().get<std::string>() : "";
        using C = CameraConvention;
        if (key == "storage")
            pickValue(c.storage, v, {{"row_major", C::Storage::row_major}, {"column_major", C::Storage::column_major}}, where, key);
        else if (key == "vectors")
            pickValue(c.vectors, v, {{"column", C::Vectors::column}, {"row", C::Vectors::row}}, where, key);
        else if (key == "handedness")
            pickValue(c.handedness, v, {{"right", C::Handedness::right}, {"left", C::Handedness::left}}, where, key);
        else if (key == "clip")
            pickValue(c.clip, v, {{"opengl", C::Clip::opengl}, {"d3d", C::Clip::d3d}, {"vulkan", C::Clip::vulkan}}, where, key);
        else throw InputError(fmt::format("{}: convention.{}: unknown key (storage, vectors, handedness, clip)", where, key));
    }
    return c;
}

template <std::size_t N> std::array<double, N> numbers(const nlohmann::json& j, const std::string& where, const char* key) {
    std::array<double, N> out{};
    if (!j.is_array() || j.size() != N) throw InputError(fmt::format("{}: {}: expected an array of {} numbers", where, key, N));
    for (std::size_t k = 0; k < N; ++k) {
        if (!j[k].is_number() || !std::isfinite(j[k].get<double>()))
            throw InputError(fmt::format("{}: {}[{}]: expected a finite number", where, key, k));
        out[k] = j[k].get<double>();
    }
    return out;
}

DVec3 vec3(const nlohmann::json& j, const std::string& where, const char* key) {
    const auto a = numbers<3>(j, where, key);
    return DVec3(a[0], a[1], a[2]);
}

CameraFileContent readJsonCameras(const std::string& name, const std::string& text) {
    const nlohmann::json root = parseJsonText(text, name, "camera file");
    if (!root.is_object())
        throw InputError(fmt::format("{}: not a camera file (a JSON object with \"frames\")", name));
    CameraFileContent out;
    for (const auto& [key, value] : root.items()) {
        if (key == "convention") out.convention = parseConvention(value, name);
        else if (key == "jitter_units") {
            out.ndcJitter = jitterInNdc(value.is_string() ? value.get<std::string>() : value.dump(), name);
        } else if (key != "frames" && key != "comment") {
            throw InputError(fmt::format("{}: {}: unknown key (convention, jitter_units, frames, comment)", name, key));
        }
    }
    const auto frames = root.find("frames");
    if (frames == root.end() || !frames->is_array() || frames->empty())
        throw InputError(fmt::format("{}: \"frames\": expected a non-empty array of cameras", name));
    for (std::size_t i = 0; i < frames->size(); ++i) {
        const nlohmann::json& f = (*frames)[i];
        const std::string where = fmt::format("{}: frames[{}]", name, i);
        if (!f.is_object()) throw InputError(fmt::format("{}: expected an object", where));
        CameraRecord r;
        const auto frame = f.find("frame");
        if (frame == f.end() || !frame->is_number_unsigned() || frame->get<std::uint64_t>() > 0xffffffffull)
            throw InputError(fmt::format("{}: \"frame\": expected the frame number (an integer >= 0)", where));
        r.frame = frame->get<std::uint32_t>();
        const bool pose = f.contains("eye"), matrix = f.contains("view");
        if (pose == matrix)
            throw InputError(fmt::format("{}: give either eye, look_at, up, fov or view, projection", where));
        r.matrices = matrix;
        for (const auto& [key, value] : f.items()) {
            if (key == "frame") continue;
            if (pose && key == "eye") r.eye = vec3(value, where, "eye");
            else if (pose && key == "look_at") r.lookAt = vec3(value, where, "look_at");
            else if (pose && key == "up") r.up = vec3(value, where, "up");
            else if (pose && key == "fov") {
                if (!value.is_number()) throw InputError(fmt::format("{}: fov: expected degrees in (0, 179)", where));
                r.fov = value.get<double>();
            } else if (matrix && key == "view") r.view = numbers<16>(value, where, "view");
            else if (matrix && key == "projection") r.projection = numbers<16>(value, where, "projection");
            else if (key == "jitter") {
                const auto j = numbers<2>(value, where, "jitter");
                r.hasJitter = true;
                r.jitter[0] = j[0];
                r.jitter[1] = j[1];
            } else {
                throw InputError(fmt::format("{}: {}: unknown key ({})", where, key,
                                             pose ? "frame, eye, look_at, up, fov, jitter" : "frame, view, projection, jitter"));
            }
        }
        if (pose && !f.contains("look_at")) throw InputError(fmt::format("{}: look_at missing", where));
        if (matrix && !f.contains("projection")) throw InputError(fmt::format("{}: projection missing", where));
        out.records.emplace_back(where + fmt::format(" (frame {})", r.frame), r);
    }
    return out;
}

/// A CSV column after 'frame': where its value goes in a record.
struct CsvColumn {
    enum Kind { eye, lookAt, up, fov, jitter, view, projection } kind;
    std::size_t index;  ///< the component: x y z, jitter x y, matrix element
    std::string name;

    static std::optional<CsvColumn> of(const std::string& name) {
        static const std::pair<const char*, Kind> vectors[] = {{"eye_", eye}, {"look_at_", lookAt}, {"up_", up}, {"jitter_", jitter}};
        for (const auto& [prefix, kind] : vectors)
            for (std::size_t i = 0; i < (kind == jitter ? 2u : 3u); ++i)
                if (name == std::string(prefix) + "xyz"[i]) return CsvColumn{kind, i, name};
        if (name == "fov") return CsvColumn{fov, 0, name};
        for (const auto& [prefix, kind] : {std::pair{"view_", view}, std::pair{"projection_", projection}})
            if (name.rfind(prefix, 0) == 0)
                if (const auto i = parseUnsigned(name.substr(std::string_view(prefix).size()), 15))
                    return CsvColumn{kind, std::size_t(*i), name};
        return std::nullopt;
    }

    void store(CameraRecord& r, double v) const {
        switch (kind) {
        case eye: r.eye[int(index)] = v; break;
        case lookAt: r.lookAt[int(index)] = v; break;
        case up: r.up[int(index)] = v; break;
        case fov: r.fov = v; break;
        case jitter: r.jitter[index] = v, r.hasJitter = true; break;
        case view: r.view[index] = v, r.matrices = true; break;
        case projection: r.projection[index] = v; break;
        }
    }
};

CameraFileContent readCsvCameras(const std::string& name, const std::string& text) {
    CameraFileContent out;
    std::istringstream in(text);
    std::string line;
    std::size_t lineNo = 0;
    std::vector<CsvColumn> columns;  ///< after 'frame'
    while (std::getline(in, line)) {
        ++lineNo;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        const std::string where = fmt::format("{}:{}", name, lineNo);
        if (line.empty()) continue;
        if (line[0] == '#') {  // "# convention = d3d", "# jitter_units = ndc"
            const auto eq = line.find('=');
            if (eq == std::string::npos) continue;
            auto trim = [](std::string s) {
                const auto b = s.find_first_not_of(" \t#"), e = s.find_last_not_of(" \t");
                return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
            };
            const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
            if (key == "convention") out.convention = parseConvention(nlohmann::json(value), where);
            else if (key == "jitter_units") out.ndcJitter = jitterInNdc(value, where);
            continue;
        }
        const std::vector<std::string> cells = splitList(line, ',');
        if (columns.empty()) {  // the header: every name known, one complete form
            if (cells.empty() || cells[0] != "frame")
                throw InputError(fmt::format("{}: the header must start with 'frame' (then eye_x.., look_at_x.., up_x.., "
                                             "fov or view_0..15, projection_0..15; jitter_x, jitter_y)", where));
            std::map<CsvColumn::Kind, std::size_t> counts;
            for (std::size_t k = 1; k < cells.size(); ++k) {
                const std::optional<CsvColumn> c = CsvColumn::of(cells[k]);
                if (!c) throw InputError(fmt::format("{}: unknown column '{}'", where, cells[k]));
                columns.push_back(*c);
                ++counts[c->kind];
            }
            const bool pose = counts[CsvColumn::eye] == 3 && counts[CsvColumn::lookAt] == 3;
            const bool matrices = counts[CsvColumn::view] == 16 && counts[CsvColumn::projection] == 16;
            if (pose == matrices)
                throw InputError(fmt::format("{}: give either eye_x..z and look_at_x..z (up, fov optional) or view_0..15 and "
                                             "projection_0..15", where));
            continue;
        }
        if (cells.size() != columns.size() + 1)
            throw InputError(fmt::format("{}: {} values, the header names {}", where, cells.size(), columns.size() + 1));
        CameraRecord r;
        const auto f = parseUnsigned(cells[0], 0xffffffffull);
        if (!f) throw InputError(fmt::format("{}: frame '{}': expected an integer >= 0", where, cells[0]));
        r.frame = std::uint32_t(*f);
        for (std::size_t k = 0; k < columns.size(); ++k) {
            const std::optional<double> v = parseNumber(cells[k + 1]);
            if (!v || !std::isfinite(*v))
                throw InputError(fmt::format("{}: {} '{}': expected a finite number", where, columns[k].name, cells[k + 1]));
            columns[k].store(r, *v);
        }
        out.records.emplace_back(where + fmt::format(" (frame {})", r.frame), r);
    }
    if (out.records.empty()) throw InputError(fmt::format("{}: no camera records", name));
    return out;
}

/// The pose of an eye / look_at / up / fov record, checked.
CameraPose poseFromLookAt(const std::string& where, const CameraRecord& r, const CameraConvention& convention) {
    // The renderer traces in float: beyond 1e15 a position keeps no digit of the disk's scale.
    constexpr double kFar = 1e15;
    for (const auto& [what, v] : {std::pair{"eye", r.eye}, std::pair{"look_at", r.lookAt}})
        if (!(std::fabs(v.x) <= kFar && std::fabs(v.y) <= kFar && std::fabs(v.z) <= kFar))
            throw InputError(fmt::format("{}: {} ({:g}, {:g}, {:g}) is farther than 1e15 from the origin: the "
                                         "renderer's float rays would lose every digit of the scene", where, what,
                                         v.x, v.y, v.z));
    if (glm::length(r.lookAt - r.eye) <= 0.0)
        throw InputError(fmt::format("{}: look_at must differ from eye", where));
    if (!(r.fov > 0.0 && r.fov < 179.0))
        throw InputError(fmt::format("{}: fov: expected degrees in (0, 179), got {}", where, r.fov));
    const DVec3 f = glm::normalize(r.lookAt - r.eye);
    if (!(glm::length(r.up) > 0.0) || glm::length(glm::cross(f, glm::normalize(r.up))) < 1e-4)
        throw InputError(fmt::format("{}: up must be non-zero and not parallel to the view direction", where));
    CameraPose pose = CameraPose::lookAt(r.eye, r.lookAt, r.up, r.fov);
    // A left-handed engine's look-at (DirectXMath's LookAtLH) puts
    // right = up x forward: the mirror of the right-handed one. The
    // record means what the engine's view matrix of it means, so a
    // file may mix both forms without the image flipping between frames.
    if (convention.handedness == CameraConvention::Handedness::left) pose.right = -pose.right;
    return pose;
}

/// A record's jitter in pixels (NDC jitter converted), which must agree
/// with its projection's off-centre terms when it has both.
void applyJitter(const std::string& where, const CameraRecord& r, const CameraFileContent& content, const CameraSettings& settings,
                 CameraPose& pose) {
    const double w = double(settings.width), h = double(settings.height), up = clipUp(content.convention);
    const double jx = content.ndcJitter ? r.jitter[0] * 0.5 * w : r.jitter[0];
    const double jy = content.ndcJitter ? -r.jitter[1] * up * 0.5 * h : r.jitter[1];
    if (r.matrices && (pose.jitterX != 0.0 || pose.jitterY != 0.0) &&
        (std::fabs(pose.jitterX - jx) > 1e-6 || std::fabs(pose.jitterY - jy) > 1e-6))
        throw InputError(fmt::format(
            "{}: jitter ({}, {}) px differs from the projection's off-centre terms ({}, {}) px{}", where, jx, jy,
            pose.jitterX, pose.jitterY,
            std::fabs(pose.jitterX + jx) <= 1e-6 && std::fabs(pose.jitterY + jy) <= 1e-6
                ? ": the opposite sign. accretion's jitter is where the sample lies from the pixel centre; a "
                  "projection that moves the image jx px right (Direct3D's TAA: _31 += 2 jx / W) samples at -jx. "
                  "Leave jitter out (it is read from the projection) or give the sample's offset "
                  "(docs/gpu-frame-loop.md#jitter)"
                : ""));
    pose.jitterX = jx;
    pose.jitterY = jy;
}

}  // namespace

CameraTrack::CameraTrack(const CameraSettings& settings) : settings_(settings) {
    if (settings.file.empty()) return;
    const std::string name = settings.file;
    const std::string bytes = readWholeFile(settings.file, "camera file");
    const std::string text(withoutBom(bytes));
    const auto first = text.find_first_not_of(" \t\r\n");
    const CameraFileContent content = first != std::string::npos && text[first] == '{' ? readJsonCameras(name, text)
                                                                                       : readCsvCameras(name, text);
    for (const auto& [where, r] : content.records) {
        CameraPose pose = r.matrices ? poseFromMatrices(fromStored(r.view, content.convention), fromStored(r.projection, content.convention),
                                                        content.convention, settings.width, settings.height, where)
                                     : poseFromLookAt(where, r, content.convention);
        if (r.hasJitter) applyJitter(where, r, content, settings, pose);
        if (!(std::fabs(pose.jitterX) <= 0.5 && std::fabs(pose.jitterY) <= 0.5))
            throw InputError(fmt::format("{}: jitter ({:.6g}, {:.6g}) px is outside the pixel ([-0.5, 0.5]); check "
                                         "jitter_units", where, pose.jitterX, pose.jitterY));
        if (!poses_.emplace(r.frame, pose).second)
            throw InputError(fmt::format("{}: frame {} given twice", where, r.frame));
    }
}

CameraPose CameraTrack::pose(std::uint32_t frame) const {
    if (settings_.file.empty()) return CameraPose::atFrame(settings_, frame);
    const auto it = poses_.find(frame);
    if (it == poses_.end())
        throw InputError(fmt::format("{}: no camera for frame {} (the file holds frames {}..{})", settings_.file, frame,
                                     poses_.begin()->first, poses_.rbegin()->first));
    return it->second;
}

std::vector<std::uint32_t> CameraTrack::missing(std::uint32_t first, std::uint32_t end) const {
    std::vector<std::uint32_t> out;
    if (settings_.file.empty()) return out;
    for (std::uint32_t f = first; f < end && out.size() < 16; ++f)
        if (!poses_.count(f)) out.push_back(f);
    return out;
}

void writeCameraFile(const std::filesystem::path& file, const CameraTrack& track, const CameraSettings& settings,
                     std::uint32_t first, std::uint32_t end, const CameraConvention& conv, bool matrices) {
    nlohmann::json doc;
    doc["comment"] = "accretion camera file: one camera per frame (see docs/gpu-frame-loop.md, Cameras from the engine)";
    doc["convention"] = {{"storage", conv.storage == CameraConvention::Storage::row_major ? "row_major" : "column_major"},
                         {"vectors", conv.vectors == CameraConvention::Vectors::row ? "row" : "column"},
                         {"handedness", conv.handedness == CameraConvention::Handedness::left ? "left" : "right"},
                         {"clip", conv.clip == CameraConvention::Clip::vulkan ? "vulkan"
                                  : conv.clip == CameraConvention::Clip::d3d   ? "d3d"
                                                                               : "opengl"}};
    if (!matrices && conv.handedness == CameraConvention::Handedness::left)
        throw InputError("--pose with a left-handed convention: an engine's eye/look_at camera there is the mirror of "
                         "accretion's right-handed one (right = up x forward); write matrices (leave out --pose)");
    doc["jitter_units"] = "pixels";
    doc["frames"] = nlohmann::json::array();
    for (std::uint32_t f = first; f < end; ++f) {
        const CameraPose p = track.pose(f);
        nlohmann::json r = {{"frame", f}};
        if (matrices) {
            Mat4 V, P;
            matricesFromPose(p, conv, settings.width, settings.height, V, P);
            r["view"] = toStored(V, conv);
            r["projection"] = toStored(P, conv);
        } else {
            r["eye"] = {p.eye.x, p.eye.y, p.eye.z};
            r["look_at"] = {p.eye.x + p.forward.x, p.eye.y + p.forward.y, p.eye.z + p.forward.z};
            r["up"] = {p.up.x, p.up.y, p.up.z};
            r["fov"] = 2.0 * std::atan(p.tanHalfFov) * 180.0 / M_PI;
            if (p.jitterX != 0.0 || p.jitterY != 0.0) r["jitter"] = {p.jitterX, p.jitterY};
        }
        doc["frames"].push_back(r);
    }
    writeFileAtomic(file, doc.dump(1) + "\n");
}

}  // namespace accretion
