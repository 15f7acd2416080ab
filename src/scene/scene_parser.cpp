#include "accretion/scene/estimator_table.h"
#include "accretion/scene/scene_parser.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <utility>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <toml++/toml.h>

#include "accretion/core/error.h"
#include "accretion/core/memory.h"
#include "accretion/core/parse.h"
#include "accretion/core/read_file.h"
#include "accretion/scene/toml_limits.h"

namespace accretion {
namespace {

std::string where(const toml::source_region& src) {
    const std::string path = src.path ? *src.path : std::string("<scene>");
    if (path.rfind("-D ", 0) == 0) return "command line " + path;
    return fmt::format("{}:{}", path, src.begin.line);
}

std::string typeName(const toml::node& n) {
    std::ostringstream s;
    s << n.type();
    return s.str();
}

/// A TOML basic string literal holding s.
std::string tomlQuote(std::string_view s) {
    std::string q = "\"";
    for (char c : s) {
        if (static_cast<unsigned char>(c) < 0x20) { q += fmt::format("\\u{:04x}", int(c)); continue; }
        if (c == '\\' || c == '"') q += '\\';
        q += c;
    }
    return q + "\"";
}

/// Overrides from the command line, each parsed as its own TOML document so
/// that its nodes carry "-D key=value" as their source.
struct Overrides {
    std::map<std::string, toml::table, std::less<>> docs;  // "section.key" -> { v = value }
    std::set<std::string, std::less<>> used;

    const toml::node* find(std::string_view dotted) const {
        auto it = docs.find(dotted);
        return it == docs.end() ? nullptr : it->second.get("v");
    }
};

Overrides parseOverrides(const std::vector<std::string>& items) {
    Overrides o;
    for (const std::string& item : items) {
        const std::string flag = "-D " + item;
        const auto eq = item.find('=');
        if (eq == std::string::npos || eq == 0)
            throw InputError(fmt::format("command line {}: expected section.key=value", flag));
        const std::string key = item.substr(0, eq);
        const std::string value = item.substr(eq + 1);
        if (std::count(key.begin(), key.end(), '.') != 1)
            throw InputError(fmt::format("command line {}: key must be section.key (e.g. render.frames)", flag));
        checkTomlNesting("v = " + value, "command line -D " + key);
        toml::table doc;
        try {
            doc = toml::parse("v = " + value, flag);
        } catch (const toml::parse_error&) {
            // A bare word (power, out/x.exr) is a string.
            doc = toml::parse("v = " + tomlQuote(value), flag);
        }
        o.docs.insert_or_assign(key, std::move(doc));
    }
    return o;
}


/// Why x is outside the range, or empty.
std::string rangeError(double x, Range range) {
    if (!std::isfinite(x)) return fmt::format("must be finite (got {})", x);
    const bool below = range.loOpen ? !(x > range.lo) : !(x >= range.lo);
    if (!below && !(x > range.hi)) return {};
    const std::string lo = range.loOpen ? fmt::format("> {}", range.lo) : fmt::format(">= {}", range.lo);
    return std::isinf(range.hi) ? fmt::format("must be {} (got {})", lo, x)
                                : fmt::format("must be {} and <= {} (got {})", lo, range.hi, x);
}

/// The ranges of the settings that command-line flags set, checked as a
/// scene file's are; errors name the flag.
class FlagRangeCheck {
public:
    explicit FlagRangeCheck(const std::map<std::string, std::string>& flags) : flags_(flags) {}
    template <class S> void section(std::string_view name, S& s) {
        section_ = name;
        s.visit(*this);
    }
    template <class T> void field(std::string_view key, const T& value, std::string_view, Range range = kAny) {
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
            const std::string dotted = fmt::format("{}.{}", section_, key);
            const auto it = flags_.find(dotted);
            if (it == flags_.end()) return;
            if (const std::string msg = rangeError(double(value), range); !msg.empty())
                throw InputError(fmt::format("{}: {}: {}", it->second, dotted, msg));
        }
    }

private:
    const std::map<std::string, std::string>& flags_;
    std::string section_;
};

/// Reads one section's fields from its table (and the overrides), checking
/// types and ranges; remembers which keys it consumed.
class SectionReader {
public:
    SectionReader(std::string_view section, const toml::table* table, Overrides& overrides)
        : section_(section), table_(table), overrides_(overrides) {}

    template <class T>
    void field(std::string_view key, T& value, std::string_view /*doc*/, Range range = kAny) {
        const std::string dotted = fmt::format("{}.{}", section_, key);
        const toml::node* node = overrides_.find(dotted);
        if (node) overrides_.used.insert(dotted);
        else if (table_) node = table_->get(key);
        if (table_ && table_->get(key)) seen_.insert(std::string(key));
        if (!node) return;
        read(*node, dotted, value, range);
        locations_[std::string(key)] = where(node->source());
    }

    const std::set<std::string>& seen() const { return seen_; }
    const std::map<std::string, std::string>& locations() const { return locations_; }

private:
    [[noreturn]] void fail(const toml::node& n, const std::string& dotted, const std::string& msg) const {
        throw InputError(fmt::format("{}: {}: {}", where(n.source()), dotted, msg));
    }

    double number(const toml::node& n, const std::string& dotted, Range range) const {
        double x;
        if (auto* f = n.as_floating_point()) x = f->get();
        else if (auto* i = n.as_integer()) x = static_cast<double>(i->get());
        else fail(n, dotted, fmt::format("expected a number, got {}", typeName(n)));
        checkRange(n, dotted, x, range);
        return x;
    }

    void checkRange(const toml::node& n, const std::string& dotted, double x, Range range) const {
        if (const std::string msg = rangeError(x, range); !msg.empty()) fail(n, dotted, msg);
    }

    void read(const toml::node& n, const std::string& dotted, SerKeySpec& v, Range) const {
        auto* str = n.as_string();
        if (!str) fail(n, dotted, fmt::format("expected a string, got {}", typeName(n)));
        std::string bad;
        const std::optional<SerKeySpec> key = parseSerKey(str->get(), bad);
        if (!key) fail(n, dotted, fmt::format("unknown component \"{}\" (expected hit, type, cluster, hint)", bad));
        v = *key;
    }
    void read(const toml::node& n, const std::string& dotted, bool& v, Range) const {
        auto* b = n.as_boolean();
        if (!b) fail(n, dotted, fmt::format("expected a boolean, got {}", typeName(n)));
        v = b->get();
    }
    template <class Int>
        requires std::is_integral_v<Int>
    void read(const toml::node& n, const std::string& dotted, Int& v, Range range) const {
        auto* i = n.as_integer();
        if (!i) fail(n, dotted, fmt::format("expected an integer, got {}", typeName(n)));
        const std::int64_t x = i->get();
        if (std::is_unsigned_v<Int> && x < 0) fail(n, dotted, fmt::format("must be >= 0 (got {})", x));
        if (static_cast<std::uint64_t>(x) > static_cast<std::uint64_t>(std::numeric_limits<Int>::max()))
            fail(n, dotted, fmt::format("too large (got {})", x));
        checkRange(n, dotted, static_cast<double>(x), range);
        v = static_cast<Int>(x);
    }
    void read(const toml::node& n, const std::string& dotted, double& v, Range range) const {
        v = number(n, dotted, range);
    }
    void read(const toml::node& n, const std::string& dotted, std::string& v, Range) const {
        auto* s = n.as_string();
        if (!s) fail(n, dotted, fmt::format("expected a string, got {}", typeName(n)));
        v = s->get();
    }
    void read(const toml::node& n, const std::string& dotted, Vec3& v, Range range) const {
        auto* a = n.as_array();
        if (!a || a->size() != 3) fail(n, dotted, "expected an array of 3 numbers");
        for (int k = 0; k < 3; ++k) v[k] = static_cast<float>(number(*a->get(k), dotted, range));
    }
    void read(const toml::node& n, const std::string& dotted, std::vector<double>& v, Range range) const {
        auto* a = n.as_array();
        if (!a) fail(n, dotted, fmt::format("expected an array of numbers, got {}", typeName(n)));
        v.clear();
        for (const toml::node& e : *a) v.push_back(number(e, dotted, range));
    }
    template <class E>
        requires std::is_enum_v<E>
    void read(const toml::node& n, const std::string& dotted, E& v, Range) const {
        auto* s = n.as_string();
        if (!s) fail(n, dotted, fmt::format("expected one of {}, got {}", enumChoices<E>(), typeName(n)));
        if (!parseEnum(s->get(), v)) fail(n, dotted, fmt::format("unknown value \"{}\" (expected {})", s->get(), enumChoices<E>()));
    }

    std::string section_;
    const toml::table* table_;
    Overrides& overrides_;
    std::set<std::string> seen_;
    std::map<std::string, std::string> locations_;
};

/// Visits every section of Settings, reading it from the document.
class SceneReader {
public:
    SceneReader(const toml::table& root, Overrides& overrides) : root_(root), overrides_(overrides) {}

    template <class S> void section(std::string_view name, S& s) {
        const toml::node* node = root_.get(name);
        const toml::table* table = nullptr;
        if (node) {
            table = node->as_table();
            if (!table) throw InputError(fmt::format("{}: [{}] must be a table, got {}", where(node->source()), name, typeName(*node)));
        }
        SectionReader reader(name, table, overrides_);
        s.visit(reader);
        if (table)
            for (auto&& [key, value] : *table)
                if (!reader.seen().count(std::string(key.str())))
                    throw InputError(fmt::format("{}: {}.{}: unknown setting", where(value.source()), name, key.str()));
        for (const auto& [k, loc] : reader.locations()) locations[fmt::format("{}.{}", name, k)] = loc;
        sections_.insert(std::string(name));
    }

    void checkUnknownSections() const {
        for (auto&& [key, value] : root_)
            if (!sections_.count(std::string(key.str())))
                throw InputError(fmt::format("{}: unknown section or key \"{}\" (sections: particles, camera, geometry, shading, render, restir, gpu)",
                                             where(value.source()), key.str()));
    }

    std::map<std::string, std::string> locations;  ///< "section.key" -> where it was set

private:
    const toml::table& root_;
    Overrides& overrides_;
    std::set<std::string> sections_;
};

/// Fails a cross-field rule at the location of the offending key.
struct RuleFailure {
    const std::map<std::string, std::string>& loc;
    std::string_view sourceName;
    [[noreturn]] void operator()(const std::string& key, const std::string& msg) const {
        auto it = loc.find(key);
        const std::string at = it != loc.end() ? it->second : std::string(sourceName);
        throw InputError(fmt::format("{}: {}: {}", at, key, msg));
    }
};

/// The disk's radii and type bands, the camera's pose and path.
void validateSceneShape(const Settings& s, const RuleFailure& fail) {
    if (!(s.particles.outer_radius > s.particles.inner_radius))
        fail("particles.outer_radius", fmt::format("must be greater than inner_radius ({})", s.particles.inner_radius));
    for (std::size_t k = 1; k < s.particles.type_bands.size(); ++k)
        if (!(s.particles.type_bands[k] > s.particles.type_bands[k - 1]))
            fail("particles.type_bands", "thresholds must increase");
    if (s.particles.type_bands.size() > 254) fail("particles.type_bands", "at most 254 thresholds");
    // The renderer traces in float: beyond 1e15 a position keeps no digit of the
    // disk's scale (and a view vector's length overflows), as camera files check.
    constexpr float kFar = 1e15f;
    for (const auto& [key, v] : {std::pair{"camera.position", s.camera.position}, std::pair{"camera.look_at", s.camera.look_at},
                                 std::pair{"camera.end_position", s.camera.end_position},
                                 std::pair{"camera.end_look_at", s.camera.end_look_at}})
        if (!(std::fabs(v.x) <= kFar && std::fabs(v.y) <= kFar && std::fabs(v.z) <= kFar))
            fail(key, fmt::format("({:g}, {:g}, {:g}) is farther than 1e15 from the origin: the renderer's float rays "
                                  "would lose every digit of the scene", v.x, v.y, v.z));
    const Vec3 view = s.camera.look_at - s.camera.position;
    if (glm::length(view) <= 0.0f) fail("camera.look_at", "must differ from camera.position");
    if (glm::length(s.camera.up) <= 0.0f || glm::length(glm::cross(glm::normalize(view), glm::normalize(s.camera.up))) < 1e-4f)
        fail("camera.up", "must be non-zero and not parallel to the view direction");
    if (!s.camera.file.empty() && s.camera.path != CameraPath::static_pose)
        fail("camera.file", "the file gives every frame's camera: leave camera.path at \"static\"");
    if (s.camera.path == CameraPath::linear && glm::length(s.camera.end_look_at - s.camera.end_position) <= 0.0f)
        fail("camera.end_look_at", "must differ from camera.end_position");
}

/// The visibility rule's far end, the frames and the output path.
void validateOutputs(const Settings& s, const RuleFailure& fail) {
    if (s.render.offset_far == FarEnd::relative && !(s.render.offset_far_margin < 1.0))
        fail("render.offset_far_margin", "a relative far-end margin must be below 1 (TMax = d (1 - e))");
    if (static_cast<std::uint64_t>(s.render.frame_start) + s.render.frames > 0xffffffffull)
        fail("render.frames", "frame_start + frames overflows");
    if (s.render.output.empty()) fail("render.output", "must not be empty");
    if (const std::string& o = s.render.output; o.size() < 5 || o.compare(o.size() - 4, 4, ".exr") != 0 || o.back() == '/' ||
                                                o[o.size() - 5] == '/')
        fail("render.output", "must be a file name ending in .exr (the EXR goes there, its previews and stats beside it)");
    if (s.render.frames > 1 && s.render.output.find("{frame}") == std::string::npos)
        fail("render.output", "a multi-frame render needs a {frame} pattern in the output path");
}

/// The packed reservoirs' light bits, render.crop, adaptive sampling's cap.
void validateSampling(const Settings& s, const RuleFailure& fail) {
    if (estimatorInfo(s.render.estimator).reuse && s.restir.layout == ReservoirLayout::packed &&
        s.particles.file.empty() && s.particles.count > (std::uint64_t(1) << s.restir.light_bits))
        fail("restir.light_bits", fmt::format("{} bits address {} lights but particles.count = {}: the packed layout needs {} bits",
                                              s.restir.light_bits, std::uint64_t(1) << s.restir.light_bits,
                                              s.particles.count, indexBits(s.particles.count)));
    if (const std::vector<double>& c = s.render.crop; !c.empty()) {
        if (c.size() != 4) fail("render.crop", fmt::format("expected [x0, x1, y0, y1] (4 numbers), got {}", c.size()));
        for (const double v : c)
            if (v != std::floor(v)) fail("render.crop", fmt::format("pixel bounds are integers (got {})", v));
        if (!(c[0] < c[1] && c[1] <= s.camera.width && c[2] < c[3] && c[3] <= s.camera.height))
            fail("render.crop", fmt::format("[{}, {}, {}, {}] is not a window of the {}x{} image (0 <= x0 < x1 <= width, "
                                            "0 <= y0 < y1 <= height; x1 and y1 are past the window)",
                                            c[0], c[1], c[2], c[3], s.camera.width, s.camera.height));
    }
    if (s.render.estimator == EstimatorKind::particle_restir) {
        const std::uint32_t t = s.restir.texels;
        if (t != 1 && t != 2 && t != 4) fail("restir.texels", fmt::format("texels per billboard side are 1, 2 or 4 (got {})", t));
        if (s.geometry.primitive == Primitive::sphere)
            fail("render.estimator", "particle_restir's texels lie on the billboards: geometry.primitive = sphere has none");
        if (s.restir.resolution_scale < 1.0)
            fail("restir.resolution_scale", "particle_restir lights the particles' texels, not a reduced image: leave it at 1");
        if (s.restir.texel_history > 0.0 && (s.restir.pixel_shading != PixelShading::interpolate || !s.restir.temporal))
            fail("restir.texel_history", "averages the texels' Lr over frames: it needs pixel_shading = interpolate and restir.temporal");
    }
    if (const double m = s.restir.crop_margin; m != -1.0) {
        if (m < 0.0 || m != std::floor(m)) fail("restir.crop_margin", fmt::format("a number of pixels, or -1 for the whole frame (got {})", m));
        if (s.render.crop.empty()) fail("restir.crop_margin", "is the margin of render.crop, which is not set");
        if (s.gpu.counters) fail("restir.crop_margin", "gpu.counters counts the GPU's dispatch, which is the whole frame");
    }
    if (s.render.target_stderr > 0.0 && !estimatorInfo(s.render.estimator).adaptive) {
        std::vector<std::string_view> adaptive;
        for (const EstimatorInfo& e : kEstimators)
            if (e.adaptive) adaptive.push_back(enumName(e.kind));
        fail("render.target_stderr", fmt::format("render.estimator = \"{}\" does not sample adaptively (only {} do): leave "
                                                 "target_stderr at 0", enumName(s.render.estimator), fmt::join(adaptive, ", ")));
    }
    if (s.render.target_stderr > 0.0 && s.render.max_samples < s.render.samples)
        fail("render.max_samples", fmt::format("must be at least render.samples ({}) when target_stderr is set", s.render.samples));
}

/// The run's memory, estimated before anything is allocated.
void checkMemory(const Settings& s, const RuleFailure& fail) {
    // Peak resident estimate from bench/results.json: ~300 B per particle
    // (particles, clusters, BVH) and ~330 B per pixel (G-buffer, images,
    // AOVs; reservoirs and history for restir), plus ~60 MB of libraries.
    // A crop holds its window's pixels alone where cropRendersAlone
    // (FramePlan::traced). Refused above
    // render.memory_limit_mb, or else above the machine's physical memory
    // (a run that cannot fit ends in an allocation failure).
    const double particles = s.particles.file.empty() ? double(s.particles.count) : 0.0;
    const std::vector<double>& crop = s.render.crop;
    const bool window = crop.size() == 4 && cropRendersAlone(s);
    const double pixels = window ? (crop[1] - crop[0]) * (crop[3] - crop[2]) : double(s.camera.width) * s.camera.height;
    const double perPixel = estimatorInfo(s.render.estimator).reuse ? 480.0 : 330.0;  // reservoirs and their history
    const double mb = (300.0 * particles + perPixel * pixels) / 1e6 + 60.0;
    const std::string image = window ? fmt::format("a {}x{} crop of {}x{}", crop[1] - crop[0], crop[3] - crop[2],
                                                   s.camera.width, s.camera.height)
                                     : fmt::format("{}x{}", s.camera.width, s.camera.height);
    const double physicalMb = double(physicalMemoryBytes()) / 1e6;
    if (s.render.memory_limit_mb > 0.0 && mb > s.render.memory_limit_mb)
        fail("render.memory_limit_mb",
             fmt::format("{} particles at {} need about {:.0f} MB, more than the limit of {:.0f} MB", particles, image,
                         mb, s.render.memory_limit_mb));
    if (s.render.memory_limit_mb <= 0.0 && physicalMb > 0.0 && mb > physicalMb)
        fail(300.0 * particles > perPixel * pixels ? "particles.count" : "camera.width",
             fmt::format("{} particles at {} need about {:.0f} MB, more than this machine's {:.0f} MB of physical "
                         "memory", particles, image, mb, physicalMb));
}

/// The candidate sources, the presampled tiles and grid, micromaps and alpha.
void validateLightingAndGeometry(const Settings& s, const RuleFailure& fail) {
    if (estimatorInfo(s.render.estimator).resampling && !estimatorInfo(s.render.estimator).reuse &&
        sourceInfo(s.render.source).presampled)
        fail("render.source", fmt::format("\"{}\" is a restir source: its presampled lights are drawn once per frame, and ris "
                                          "averages many samples of one frame, which would converge to that frame's draw, not "
                                          "to Lr (use uniform, power or tree)", enumName(s.render.source)));
    if (estimatorInfo(s.render.estimator).passes == LightingPasses::voxelCache && sourceInfo(s.render.source).presampled)
        fail("render.source", fmt::format("\"{}\" is a restir source (presampled once per frame for its pixels): the voxel cache "
                                          "draws its cells' lights from uniform, power or tree", enumName(s.render.source)));
    if (s.render.estimator == EstimatorKind::particle_split && s.particle_split.near == 0 && s.particle_split.far == 0)
        fail("particle_split.far", "particle_split.near and particle_split.far are both 0: no light reaches a texel");
    if (s.render.estimator == EstimatorKind::particle_split && s.particle_split.far_new > 0) {
        if (s.particle_split.history <= 0.0)
            fail("particle_split.far_new", "far_new draws more far rays for a texel without history: set particle_split.history "
                                           "(without one every texel draws far)");
        if (s.particle_split.far_new < s.particle_split.far)
            fail("particle_split.far_new", fmt::format("must be 0 or at least particle_split.far ({})", s.particle_split.far));
    }
    if (s.render.estimator == EstimatorKind::particle_split && s.particle_split.far_share > 0 &&
        (s.particle_split.history <= 0.0 || s.particle_split.history_of != HistoryOf::far))
        fail("particle_split.far_share", "far_share blends a texel's far mean with its neighbours' far histories: set "
                                         "particle_split.history and history_of = \"far\"");
    if (s.render.estimator == EstimatorKind::particle_split && s.particle_split.far_handoff &&
        (s.particle_split.history <= 0.0 || s.particle_split.history_of != HistoryOf::far || s.particle_split.near == 0))
        fail("particle_split.far_handoff", "far_handoff moves lights between a texel's far history and its near sum: set "
                                           "particle_split.history, history_of = \"far\" and near");
    if (s.render.estimator == EstimatorKind::particle_split && s.particle_split.far_prior > 0) {
        if (s.particle_split.history <= 0.0 || s.particle_split.history_of != HistoryOf::far)
            fail("particle_split.far_prior", "far_prior starts a new texel's far mean from its neighbours' far histories: set "
                                             "particle_split.history and history_of = \"far\"");
        if (s.particle_split.far == 0 && s.particle_split.far_new == 0)
            fail("particle_split.far_prior", "far_prior weighs a prior against a texel's far rays: particle_split.far is 0");
    }
    if (static_cast<std::uint64_t>(s.restir.regir_cells) * s.restir.regir_cells * s.restir.regir_cells * s.restir.regir_lights_per_cell >
        (std::uint64_t(1) << 28))
        fail("restir.regir_lights_per_cell", fmt::format("{}^3 cells x {} lights is more than 2^28 slots", s.restir.regir_cells,
                                                         s.restir.regir_lights_per_cell));
    if (std::uint64_t(s.restir.tile_count) * s.restir.tile_size > (std::uint64_t(1) << 28))
        fail("restir.tile_size", fmt::format("{} tiles x {} lights is more than 2^28 entries", s.restir.tile_count, s.restir.tile_size));
    if (s.gpu.omm != OmmMode::off && s.geometry.alpha != AlphaMode::disc)
        fail("gpu.omm", "opacity micromaps apply to disc-alpha billboards (geometry.alpha = \"disc\")");
    if (s.geometry.primitive == Primitive::sphere && s.geometry.alpha == AlphaMode::disc)
        fail("geometry.alpha", "disc alpha applies to billboards only (primitive = \"sphere\")");
    // Designs no GPU builds, refused here for every command (cost would
    // price them, the twin could not run them).
    if (s.gpu.omm != OmmMode::off && s.geometry.layout == AccelLayout::aabbs)
        fail("gpu.omm", "opacity micromaps are built over triangles; geometry.layout = \"aabbs\" holds procedural boxes, whose "
                        "intersection program tests the disc itself");
    if (s.geometry.layout == AccelLayout::instances && s.geometry.build != BuildPolicy::rebuild && s.geometry.build != BuildPolicy::refit)
        fail("geometry.build", fmt::format("\"{}\" is a policy of cluster BLASes; geometry.layout = \"instances\" shares one BLAS "
                                           "and rebuilds or refits its TLAS (rebuild or refit)", enumName(s.geometry.build)));
}

/// Cross-field rules, reported at the location of the offending key, in this order.
void validate(const Settings& s, const std::map<std::string, std::string>& loc, std::string_view sourceName) {
    const RuleFailure fail{loc, sourceName};
    validateSceneShape(s, fail);
    validateOutputs(s, fail);
    validateSampling(s, fail);
    checkMemory(s, fail);
    validateLightingAndGeometry(s, fail);
}

/// A setting's value as TOML text; floats in their shortest round-trip form.
std::string tomlValue(bool v) { return v ? "true" : "false"; }
std::string tomlValue(const std::string& v) { return tomlQuote(v); }
template <class F>
    requires std::is_floating_point_v<F>
std::string tomlValue(F v) {
    char buf[64];
    const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
    std::string text(buf, end);
    if (text.find_first_of(".e") == std::string::npos) text += ".0";  // keep it a TOML float
    return text;
}
template <class Int>
    requires(std::is_integral_v<Int> && !std::is_same_v<Int, bool>)
std::string tomlValue(Int v) { return std::to_string(v); }
std::string tomlValue(const SerKeySpec& k) { return tomlQuote(formatSerKey(k)); }
std::string tomlValue(const Vec3& v) {
    return fmt::format("[{}, {}, {}]", tomlValue(v.x), tomlValue(v.y), tomlValue(v.z));
}
std::string tomlValue(const std::vector<double>& v) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + tomlValue(v[i]);
    return out + "]";
}
template <class E>
    requires std::is_enum_v<E>
std::string tomlValue(E e) { return tomlQuote(enumName(e)); }

/// Writes the effective settings as TOML, or (with docs) the reference list.
class TomlWriter {
public:
    explicit TomlWriter(bool withDocs) : withDocs_(withDocs) {}
    template <class S> void section(std::string_view name, S& s) {
        out += fmt::format("{}[{}]\n", out.empty() ? "" : "\n", name);
        s.visit(*this);
    }
    template <class T> void field(std::string_view key, const T& value, std::string_view doc, Range = kAny) {
        const std::string line = fmt::format("{} = {}", key, tomlValue(value));
        if (!withDocs_) out += line + "\n";
        else out += fmt::format("{:<44} # {}{}\n", line, doc, choices<T>());
    }
    std::string out;

private:
    template <class T> static std::string choices() {
        if constexpr (std::is_enum_v<T>) return " (" + enumChoices<T>() + ")";
        return "";
    }
    bool withDocs_;
};

}  // namespace

Settings parseScene(std::string_view text, std::string_view sourceName, const std::vector<std::string>& overrideItems,
                    const std::vector<FlagSetting>& flags) {
    checkTomlNesting(text, sourceName);
    toml::table root;
    try {
        root = toml::parse(text, sourceName);
    } catch (const toml::parse_error& e) {
        throw InputError(fmt::format("{}: {}", where(e.source()), e.description()));
    }
    Overrides overrides = parseOverrides(overrideItems);
    Settings settings;
    SceneReader reader(root, overrides);
    settings.visit(reader);
    reader.checkUnknownSections();
    for (const auto& [key, doc] : overrides.docs)
        if (!overrides.used.count(key))
            throw InputError(fmt::format("command line -D {}: unknown setting (see accretion render --help-settings)", key));
    std::map<std::string, std::string> flagged;  // "section.key" -> "command line --flag value"
    for (const FlagSetting& f : flags) {
        f.apply(settings);
        flagged[f.key] = reader.locations[f.key] = "command line " + f.flag;
    }
    FlagRangeCheck check(flagged);
    settings.visit(check);
    validate(settings, reader.locations, sourceName);
    return settings;
}

Settings loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides,
                   const std::vector<FlagSetting>& flags) {
    Settings s = parseScene(readWholeFile(file, "scene file"), file.string(), overrides, flags);
    s.scenePath = file.string();
    s.sceneName = file.stem().string();
    // A relative particle file is found next to the scene, wherever it runs from.
    const std::filesystem::path particles(s.particles.file);
    if (!particles.empty() && particles.is_relative() && !file.parent_path().empty())
        s.particles.file = (file.parent_path() / particles).string();
    const std::filesystem::path cameras(s.camera.file);
    if (!cameras.empty() && cameras.is_relative() && !file.parent_path().empty())
        s.camera.file = (file.parent_path() / cameras).string();
    return s;
}

std::string settingsToToml(const Settings& settings) {
    TomlWriter w(false);
    Settings copy = settings;  // visit() is non-const: it also drives the reader
    copy.visit(w);
    return w.out;
}

std::string settingsReference() {
    Settings defaults;
    TomlWriter w(true);
    defaults.visit(w);
    return w.out;
}

std::pair<std::uint64_t, std::uint64_t> parseHalfOpen(const std::string& text, const char* option) {
    const auto colon = text.find(':');
    auto number = [&](const std::string& s) -> std::uint64_t {
        const std::optional<std::uint64_t> v = parseUnsigned(s);
        if (!v) throw InputError(fmt::format("command line {} {}: expected A:B with 0 <= A < B", option, text));
        return *v;
    };
    const std::uint64_t a = number(text.substr(0, colon));
    const std::uint64_t b = colon == std::string::npos ? a + 1 : number(text.substr(colon + 1));
    if (b <= a)
        throw InputError(fmt::format("command line {} {}: end must be greater than start (half-open A:B)", option, text));
    if (b > 0xffffffffull)
        throw InputError(fmt::format("command line {} {}: frames are 32-bit numbers (the last is 4294967294)", option, text));
    return {a, b};
}

std::vector<FlagSetting> frameFlags(const std::string& frames) {
    if (frames.empty()) return {};
    const auto [a, b] = parseHalfOpen(frames, "--frames");
    const std::string flag = "--frames " + frames;
    return {{"render.frame_start", flag, [a = a](Settings& s) { s.render.frame_start = std::uint32_t(a); }},
            {"render.frames", flag, [n = b - a](Settings& s) { s.render.frames = std::uint32_t(n); }}};
}

}  // namespace accretion
