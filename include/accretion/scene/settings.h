#pragma once
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// Closed/open numeric bounds of a setting, checked at load.
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;  ///< lo itself is excluded
};
inline constexpr Range kAny{};
inline constexpr Range kPositive{0.0, std::numeric_limits<double>::infinity(), true};
inline constexpr Range kNonNegative{0.0, std::numeric_limits<double>::infinity(), false};
inline constexpr Range kUnit{0.0, 1.0, false};
/// A positive length: beyond 1e9 squared distances leave float range.
inline constexpr Range kLength{0.0, 1e9, true};

/// Names of an enum's values, index = underlying value.
template <class E> struct EnumNames;

#define ACC_ENUM_NAMES(E, ...)                                                  \
    template <> struct EnumNames<E> {                                           \
        static constexpr auto names = std::to_array<std::string_view>({__VA_ARGS__}); \
    }

enum class CameraPath { static_pose, orbit, linear };
enum class SerComponent : std::uint8_t { hit, type, cluster, hint };
enum class Primitive { billboard, sphere };
enum class Orientation { view_plane, view_point, velocity };
enum class AlphaMode { opaque, disc };
enum class BuildPolicy { rebuild, refit, fast_trace, partial };
enum class AccelLayout { clusters, instances, aabbs };
enum class CpuLayout { fastest, gpu };
enum class ShadingModel { lambert, sphere, isotropic };
enum class EstimatorKind { exact, uniform, power, ris, restir, tree, split, particle_restir, voxel_cache, particle_split };
enum class PixelShading { interpolate, resample };
enum class TexelPoint { centre, jittered, antithetic };
/// particle_split.history_of: which of a texel's terms its history averages.
enum class HistoryOf { all, far };
/// particle_split.history_start: how a texel's average starts.
enum class HistoryStart { first, mean };
enum class VoxelBasis { l1, camera };
enum class BiasCorrection { none, basic, pairwise };
enum class ReservoirLayout { full, packed };
enum class LightSource { uniform, power, tree, tiles, regir };
enum class OmmMode { off, two_state, four_state };
enum class NonFinitePolicy { zero_sample, discard };
enum class VisibilityRule { exact, offset };
enum class OffsetOrigin { tmin, waechter_binder };
enum class FarEnd { absolute, relative };
enum class ToneMap { filmic, log, linear };

ACC_ENUM_NAMES(CameraPath, "static", "orbit", "linear");
ACC_ENUM_NAMES(SerComponent, "hit", "type", "cluster", "hint");
ACC_ENUM_NAMES(Primitive, "billboard", "sphere");
ACC_ENUM_NAMES(Orientation, "view_plane", "view_point", "velocity");
ACC_ENUM_NAMES(AlphaMode, "opaque", "disc");
ACC_ENUM_NAMES(BuildPolicy, "rebuild", "refit", "fast_trace", "partial");
ACC_ENUM_NAMES(AccelLayout, "clusters", "instances", "aabbs");
ACC_ENUM_NAMES(CpuLayout, "fastest", "gpu");
ACC_ENUM_NAMES(ShadingModel, "lambert", "sphere", "isotropic");
ACC_ENUM_NAMES(EstimatorKind, "exact", "uniform", "power", "ris", "restir", "tree", "split", "particle_restir", "voxel_cache",
               "particle_split");
ACC_ENUM_NAMES(PixelShading, "interpolate", "resample");
ACC_ENUM_NAMES(TexelPoint, "centre", "jittered", "antithetic");
ACC_ENUM_NAMES(HistoryOf, "all", "far");
ACC_ENUM_NAMES(HistoryStart, "first", "mean");
ACC_ENUM_NAMES(VoxelBasis, "l1", "camera");
ACC_ENUM_NAMES(BiasCorrection, "none", "basic", "pairwise");
ACC_ENUM_NAMES(ReservoirLayout, "full", "packed");
ACC_ENUM_NAMES(LightSource, "uniform", "power", "tree", "tiles", "regir");
ACC_ENUM_NAMES(OmmMode, "off", "2state", "4state");
ACC_ENUM_NAMES(NonFinitePolicy, "zero_sample", "discard");
ACC_ENUM_NAMES(VisibilityRule, "exact", "offset");
ACC_ENUM_NAMES(OffsetOrigin, "tmin", "waechter_binder");
ACC_ENUM_NAMES(FarEnd, "absolute", "relative");
ACC_ENUM_NAMES(ToneMap, "filmic", "log", "linear");

template <class E> constexpr std::string_view enumName(E e) {
    return EnumNames<E>::names[static_cast<std::size_t>(e)];
}

/// The value named `text` (the inverse of enumName); false if none is.
template <class E> constexpr bool parseEnum(std::string_view text, E& out) {
    const auto& names = EnumNames<E>::names;
    for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == text) {
            out = static_cast<E>(i);
            return true;
        }
    return false;
}

/// "a | b | c": every name of an enum, for messages.
template <class E> std::string enumChoices() {
    std::string c;
    for (auto nm : EnumNames<E>::names) c += (c.empty() ? "" : " | ") + std::string(nm);
    return c;
}

// Each settings struct lists its fields once, in visit(): the same table
// drives parsing (with validation), writing the effective settings, and help.
// v.field(key, member, doc, range).

/// [particles]: the accretion-disk generator (docs/MODEL.md section 1) or a file.
struct ParticleSettings {
    std::string file;                  ///< particle file(s), `{frame}` pattern; empty = generator
    std::uint32_t count = 10000;       ///< number of generated particles
    Vec3 center{0.0f, 0.0f, 0.0f};     ///< centre of the generated disk
    std::uint64_t seed = 1;            ///< generator seed
    double inner_radius = 1.0;         ///< disk inner radius
    double outer_radius = 10.0;        ///< disk outer radius
    double thickness = 0.25;           ///< height standard deviation at the outer radius (flared)
    double radius = 0.04;              ///< particle radius
    double radius_jitter = 0.5;        ///< relative uniform jitter of the radius, in [0,1)
    double gm = 20.0;                  ///< gravitational parameter G*M of the central mass
    double time_step = 0.02;           ///< simulated time between frames
    double inner_temperature = 12000;  ///< temperature at the inner radius, kelvin
    double temperature_exponent = 0.75;///< T(r) = T_in (r / r_in)^(-exponent)
    double luminosity = 1.0;           ///< intensity (luminance) of a particle at T_in
    std::vector<double> type_bands = {4500.0, 7500.0}; ///< temperature thresholds between particle types
    double opacity = 1.0;              ///< opacity written to the GPU buffer

    template <class V> void visit(V& v) {
        v.field("file", file, "particle file path (raw .bin or .ply; relative to the scene file), {frame} pattern; empty: use the generator");
        v.field("count", count, "number of generated particles", Range{1, 5e7});
        v.field("center", center, "centre of the generated disk (|x| <= 1e9)", Range{-1e9, 1e9});
        v.field("seed", seed, "generator seed");
        v.field("inner_radius", inner_radius, "disk inner radius", kLength);
        v.field("outer_radius", outer_radius, "disk outer radius (> inner_radius)", kLength);
        v.field("thickness", thickness, "height standard deviation at the outer radius", Range{0.0, 1e9});
        v.field("radius", radius, "particle radius", kLength);
        v.field("radius_jitter", radius_jitter, "relative radius jitter in [0,1)", Range{0.0, 0.999});
        v.field("gm", gm, "gravitational parameter GM (Keplerian angular speed sqrt(GM/r^3))", kNonNegative);
        v.field("time_step", time_step, "simulated time between frames", kNonNegative);
        v.field("inner_temperature", inner_temperature, "temperature at the inner radius (K)", Range{100.0, 1e6});
        v.field("temperature_exponent", temperature_exponent, "T(r) = T_in (r/r_in)^-exponent", Range{0.0, 4.0});
        v.field("luminosity", luminosity, "luminance of a particle at the inner temperature", kNonNegative);
        v.field("type_bands", type_bands, "increasing temperature thresholds (K) between particle types", Range{0.0, 1e7});
        v.field("opacity", opacity, "particle opacity", kUnit);
    }
};

/// [camera]: pinhole camera and its path over frames.
struct CameraSettings {
    Vec3 position{0.0f, 7.0f, 17.0f};  ///< eye position at frame 0
    Vec3 look_at{0.0f, 0.0f, 0.0f};    ///< target point at frame 0
    Vec3 up{0.0f, 1.0f, 0.0f};         ///< up direction
    double fov = 45.0;                 ///< vertical field of view, degrees
    std::uint32_t width = 640;         ///< image width, pixels
    std::uint32_t height = 360;        ///< image height, pixels
    CameraPath path = CameraPath::static_pose; ///< pose over frames
    double orbit_speed = 1.0;          ///< orbit: degrees per frame around the y axis through look_at
    Vec3 end_position{0.0f, 7.0f, 17.0f}; ///< linear: eye position at frame path_frames
    Vec3 end_look_at{0.0f, 0.0f, 0.0f};   ///< linear: target at frame path_frames
    std::uint32_t path_frames = 100;   ///< linear: frames from start to end pose
    std::string file;                  ///< the engine's cameras per frame (JSON or CSV; relative to the scene file)

    template <class V> void visit(V& v) {
        v.field("position", position, "eye position at frame 0");
        v.field("look_at", look_at, "target point at frame 0");
        v.field("up", up, "up direction");
        v.field("fov", fov, "vertical field of view in degrees", Range{0.0, 179.0, true});
        v.field("width", width, "image width in pixels", Range{1, 16384});
        v.field("height", height, "image height in pixels", Range{1, 16384});
        v.field("path", path, "camera path over frames");
        v.field("orbit_speed", orbit_speed, "orbit: degrees per frame around the y axis", Range{-360.0, 360.0});
        v.field("end_position", end_position, "linear: eye position at frame path_frames");
        v.field("end_look_at", end_look_at, "linear: target at frame path_frames");
        v.field("path_frames", path_frames, "linear: frames from start to end pose", Range{1, 1e9});
        v.field("file", file, "the engine's camera of each frame (JSON or CSV, relative to the scene file: pose or "
                              "view/projection matrices, jitter); empty: the path above");
    }
};

/// [geometry]: what the GPU's BLAS/TLAS hold (docs/MODEL.md section 2).
struct GeometrySettings {
    Primitive primitive = Primitive::billboard;      ///< billboard quads or procedural spheres
    Orientation orientation = Orientation::view_plane; ///< billboard facing
    AlphaMode alpha = AlphaMode::opaque;             ///< billboard alpha test
    AccelLayout layout = AccelLayout::clusters;      ///< how the particles become BLASes and TLAS instances
    std::uint32_t cluster_size = 100;                ///< target particles per cluster (one BLAS each)
    CpuLayout cpu_layout = CpuLayout::fastest;       ///< what the CPU renderer traces (images do not depend on it)
    BuildPolicy build = BuildPolicy::rebuild;        ///< per-frame BLAS policy
    double rebuild_fraction = 0.7;                   ///< partial: fraction of clusters rebuilt per frame (the GPU pipeline's: 70%)
    bool watertight = false;                         ///< Embree robust mode: watertight quads (slower)

    template <class V> void visit(V& v) {
        v.field("primitive", primitive, "particle geometry");
        v.field("orientation", orientation, "billboard orientation");
        v.field("alpha", alpha, "billboard alpha: opaque quad or alpha-tested disc");
        v.field("layout", layout,
                "acceleration layout: clusters (a BLAS of triangles or spheres per cluster; cluster_size >= the "
                "particle count gives one BLAS), instances (one BLAS of one unit billboard, one TLAS instance per "
                "particle), aabbs (a BLAS of procedural boxes per cluster, one per particle, with an intersection program)");
        v.field("cpu_layout", cpu_layout,
                "what the CPU renderer traces: fastest (one Embree BVH of every particle; the image does not depend on "
                "the layout) or gpu (geometry.layout and cluster_size). Counting (cost, gpu.counters) and the partial "
                "build policy, whose stale clusters change the image, always trace the GPU's layout");
        v.field("cluster_size", cluster_size, "target particles per cluster (one BLAS each)", Range{1, 1e7});
        v.field("build", build, "per-frame BLAS policy (partial: rebuild_fraction of the clusters, the rest stale)");
        v.field("rebuild_fraction", rebuild_fraction, "partial: fraction of clusters rebuilt per frame, round robin", Range{0.0, 1.0, true});
        v.field("watertight", watertight, "Embree's robust mode: no ray slips between a quad's two triangles along the diagonal (~30% slower rays; off, a segment within float rounding of a diagonal can pass)");
    }
};

/// [shading]: the shading equation (docs/MODEL.md section 3).
struct ShadingSettings {
    ShadingModel model = ShadingModel::lambert; ///< BRDF and cosine
    Vec3 albedo{0.8f, 0.8f, 0.8f};              ///< particle albedo rho
    double self_emission = 1.0;                 ///< s_e in Le = s_e I
    double dmin = 0.0;                          ///< global distance clamp; dmin_i = max(r_i, dmin)
    Vec3 background{0.0f, 0.0f, 0.0f};          ///< radiance of a miss
    bool visibility = true;                     ///< V(x, p_i) by shadow rays; false: V = 1 (no shadow rays)

    template <class V> void visit(V& v) {
        v.field("model", model, "shading model");
        v.field("albedo", albedo, "particle albedo rho (RGB)", kUnit);
        v.field("self_emission", self_emission, "self-emission scale s_e", kNonNegative);
        v.field("dmin", dmin, "global distance clamp (dmin_i = max(r_i, dmin))", kNonNegative);
        v.field("background", background, "background radiance (RGB)", kNonNegative);
        v.field("visibility", visibility, "shadow rays for V(x, p_i); false: every light visible (no shadow rays)");
    }
};

/// [render]: frames, estimator and outputs.
struct RenderSettings {
    std::uint32_t frame_start = 0;               ///< first frame rendered
    std::uint32_t frames = 1;                    ///< number of frames rendered
    EstimatorKind estimator = EstimatorKind::exact; ///< estimator of Lr
    std::uint32_t samples = 16;                  ///< light samples per pixel (Monte Carlo estimators)
    std::uint32_t candidates = 16;               ///< ris, restir: candidates M per reservoir (the GPU pipeline's: 16)
    LightSource source = LightSource::uniform;   ///< ris, restir: source of the candidates (uniform, power, the light tree at the receiver; restir also RTXDI's light tiles and ReGIR grid)
    double target_stderr = 0.0;                  ///< tree, split, uniform, power: relative standard error to reach per pixel (0: fixed samples)
    std::uint32_t near_lights = 0;               ///< split: lights summed exactly per receiver, its nearest (0: automatic)
    std::uint32_t max_samples = 65536;           ///< cap of the adaptive sampling of target_stderr
    std::uint64_t seed = 0;                      ///< render seed
    std::string output = "out/{scene}.{frame}.exr"; ///< EXR path, {scene} and {frame} patterns
    VisibilityRule visibility_rule = VisibilityRule::exact; ///< V by identity exclusion (docs/MODEL.md section 3), or a GPU epsilon rule
    OffsetOrigin offset_origin = OffsetOrigin::tmin; ///< offset rule: TMin along the ray, or Waechter-Binder along the normal
    double offset_tmin = 1e-3;                   ///< offset rule, tmin: the ray's TMin (the GPU pipeline's: 0.001)
    FarEnd offset_far = FarEnd::absolute;        ///< offset rule: TMax = d - e (the GPU pipeline's) or d (1 - e)
    double offset_far_margin = 1e-3;             ///< offset rule: the far-end margin e
    NonFinitePolicy nonfinite = NonFinitePolicy::zero_sample; ///< a NaN/Inf sample counts as 0, or is discarded (restir: its reservoir)
    double memory_limit_mb = 0.0;                ///< refuse runs estimated to need more (0: no limit)
    double exposure = 0.0;                       ///< preview exposure in stops, added to auto exposure
    bool auto_exposure = true;                   ///< preview: exposure from the image (see tonemap)
    ToneMap tonemap = ToneMap::filmic;           ///< preview tone curve
    std::vector<double> crop;                    ///< [x0, x1, y0, y1]: render only this pixel window (empty: the whole image)

    template <class V> void visit(V& v) {
        v.field("frame_start", frame_start, "first frame", Range{0, 1e9});
        v.field("frames", frames, "number of frames", Range{1, 1e6});
        v.field("estimator", estimator, "estimator of the reflected light Lr");
        v.field("samples", samples, "light samples per pixel (uniform, power; ris: reservoirs)", Range{1, 1e7});
        v.field("candidates", candidates, "ris, restir: candidates M per reservoir", Range{1, 1e6});
        v.field("source", source, "ris, restir: source of the candidates: uniform, power, tree (the light tree at the receiver); restir only: tiles (RTXDI's presampled light tiles, [restir] tile_*) or regir (a world-space grid of light reservoirs, [restir] regir_*)");
        v.field("near_lights", near_lights, "split: the k nearest lights of each receiver are summed exactly, the rest sampled from the light tree without them (0: automatic, see docs/MODEL.md section 4)", Range{0, 1024});
        v.field("target_stderr", target_stderr, "tree, split, uniform, power: per-pixel relative standard error to reach, adding `samples` per round (0: off)", Range{0.0, 1.0});
        v.field("max_samples", max_samples, "cap on samples per pixel when target_stderr is set", Range{1, 1e9});
        v.field("seed", seed, "render seed");
        v.field("output", output, "EXR output path; {scene} and {frame} are replaced");
        v.field("visibility_rule", visibility_rule, "V(x, p_i): exact (the receiver and the light excluded by identity: the reference) or offset (a GPU epsilon rule, measured as a bias)");
        v.field("offset_origin", offset_origin, "offset rule: tmin (TMin = offset_tmin along the ray) or waechter_binder (origin moved along the normal, ray re-aimed at p_i)");
        v.field("offset_tmin", offset_tmin, "offset rule, tmin: the ray's TMin (the GPU pipeline's: 0.001)", kNonNegative);
        v.field("offset_far", offset_far, "offset rule: far end absolute (TMax = d - e, the GPU pipeline's) or relative (TMax = d (1 - e))");
        v.field("offset_far_margin", offset_far_margin, "offset rule: the far-end margin e (absolute: a length; relative: a fraction < 1)", Range{0.0, 1e9});
        v.field("nonfinite", nonfinite, "a NaN/Inf sample: zero_sample (counts as 0) | discard (not counted; restir: the reservoir is emptied)");
        v.field("memory_limit_mb", memory_limit_mb, "refuse a run whose estimated peak memory exceeds this (MB; 0: no limit)", kNonNegative);
        v.field("exposure", exposure, "preview exposure (stops)", Range{-64.0, 64.0});
        v.field("auto_exposure", auto_exposure, "preview: exposure from the image (filmic: the median lit luminance to 0.18; log: the median to 1; linear: the 99.5th percentile to 1)");
        v.field("tonemap", tonemap, "preview curve: filmic (ACES fit: the whole disk, highlights rolled off), log (log2(1 + x), to the 99.9th percentile) or linear (clipped)");
        v.field("crop", crop, "[x0, x1, y0, y1]: render only the pixels x0 <= x < x1, y0 <= y < y1 (the EXR's data window; empty: all)", Range{0, 16384});
    }
};

/// [restir]: ReSTIR DI reuse (docs/MODEL.md section 4; the GPU pipeline's tuning
/// checklist gives the defaults: M cap 20, 5 neighbours, 30 px, 1 iteration).
struct RestirSettings {
    bool temporal = true;                    ///< temporal reuse
    double m_cap = 20.0;                     ///< history M capped at m_cap x current M
    std::uint32_t spatial_neighbours = 5;    ///< k neighbours per spatial pass (0: no spatial reuse)
    double spatial_radius = 30.0;            ///< neighbour disc radius, pixels
    std::uint32_t spatial_iterations = 1;    ///< spatial passes
    BiasCorrection bias_correction = BiasCorrection::basic; ///< normalisation of reused samples
    bool basic_visibility = false;           ///< basic: also trace a shadow ray from each neighbour (unbiased with visibility reuse)
    bool visibility_reuse = false;           ///< discard an occluded sample before storing it for the next frame
    bool candidate_visibility = false;       ///< one more shadow ray: drop an occluded initial candidate before reuse
    double normal_threshold = 0.9;           ///< reject a neighbour whose normal . n is below this
    double depth_threshold = 0.1;            ///< reject a neighbour whose depth differs by more than this fraction
    double resolution_scale = 1.0;           ///< lighting resolution relative to the image (bilateral upsample)
    double crop_margin = -1.0;               ///< with render.crop: the pixels around it restir renders for its reuse (-1: the whole frame)
    ReservoirLayout layout = ReservoirLayout::full; ///< stored reservoir: full (16 B) or packed
    std::uint32_t light_bits = 20;           ///< packed: bits of the light index (the rest of 32 hold M)
    bool half_weights = true;                ///< packed: W and p_hat as half floats (8 B) rather than floats (12 B)
    // Candidate sources tiles and regir, with RTXDI's defaults (its
    // RISBufferSegmentParameters and ReGIR grid parameters).
    std::uint32_t tile_count = 128;          ///< tiles: presampled tiles per frame (RTXDI tileCount)
    std::uint32_t tile_size = 1024;          ///< tiles: lights per tile (RTXDI tileSize)
    std::uint32_t regir_cells = 16;          ///< regir: cells per axis (RTXDI GridSize 16 x 16 x 16)
    double regir_cell_size = 0.0;            ///< regir: cell edge in scene units (0: the grid fits the particles; RTXDI regirCellSize, 1)
    std::uint32_t regir_lights_per_cell = 512; ///< regir: reservoirs per cell (RTXDI LightsPerCell)
    std::uint32_t regir_build_samples = 8;   ///< regir: candidates per cell reservoir (RTXDI regirNumBuildSamples)
    double regir_jitter = 1.0;               ///< regir: receiver jitter in cells (RTXDI regirSamplingJitter)
    // particle_restir (docs/MODEL.md section 4b): reservoirs on the visible
    // particles' billboards, not on the pixels.
    std::uint32_t texels = 1;                ///< particle_restir: texels per billboard side (1: one reservoir a particle, 2: 2x2, 4: 4x4)
    std::uint32_t texel_rays = 1;            ///< particle_restir: independent reservoirs (one shadow ray each) per texel
    PixelShading pixel_shading = PixelShading::interpolate; ///< particle_restir: how a pixel reads its particle's texels
    std::uint32_t world_neighbours = 8;      ///< particle_restir: spatial reuse draws among this many visible particles either side in Morton order
    double texel_history = 0.0;              ///< particle_restir, interpolate: weight of a texel's last Lr in its new one (0: none)

    template <class V> void visit(V& v) {
        v.field("temporal", temporal, "temporal reuse through particle motion and the previous camera");
        v.field("m_cap", m_cap, "history M capped at m_cap x the current M", Range{0.0, 1e6});
        v.field("spatial_neighbours", spatial_neighbours, "neighbours per spatial pass (0: no spatial reuse)", Range{0, 64});
        v.field("spatial_radius", spatial_radius, "spatial neighbour disc radius in pixels", Range{0.0, 4096.0});
        v.field("spatial_iterations", spatial_iterations, "spatial reuse passes", Range{0, 16});
        v.field("bias_correction", bias_correction, "none (1/M, biased), basic (1/Z over neighbours with p_hat > 0) or pairwise MIS");
        v.field("basic_visibility", basic_visibility, "basic: count a visibility-tested neighbour only if it also sees the sample (shadow ray): unbiased with visibility reuse");
        v.field("visibility_reuse", visibility_reuse, "zero W of an occluded sample before storing it for the next frame");
        v.field("candidate_visibility", candidate_visibility, "trace a shadow ray for the initial candidate and drop it if occluded, before any reuse (Bitterli et al. Alg. 5)");
        v.field("normal_threshold", normal_threshold, "neighbour rejection: minimum normal dot product", Range{-1.0, 1.0});
        v.field("depth_threshold", depth_threshold, "neighbour rejection: maximum relative depth difference", kNonNegative);
        v.field("resolution_scale", resolution_scale, "lighting resolution / image resolution (bilateral upsample)", Range{0.0, 1.0, true});
        v.field("crop_margin", crop_margin, "with render.crop: restir renders the crop and this many pixels around it (a window of the frame, aligned to 8 pixels), not the whole frame; a neighbour or history beyond it is off-screen (-1: the whole frame)", Range{-1.0, 16384.0});
        v.field("layout", layout, "stored reservoir layout: full (16 B) or packed (light index + M in 32 bits, weights)");
        v.field("light_bits", light_bits, "packed: light index bits (M gets 32 - light_bits)", Range{1, 31});
        v.field("half_weights", half_weights, "packed: W and p_hat as half floats (8 B) instead of floats (12 B)");
        v.field("tile_count", tile_count, "render.source = tiles or regir: light tiles presampled per frame (RTXDI tileCount)", Range{1, 65536});
        v.field("tile_size", tile_size, "render.source = tiles or regir: lights per tile, drawn by power (RTXDI tileSize)", Range{1, 1 << 20});
        v.field("regir_cells", regir_cells, "render.source = regir: grid cells per axis (RTXDI GridSize)", Range{1, 128});
        v.field("regir_cell_size", regir_cell_size, "render.source = regir: cell edge in scene units, the grid centred on the particles (0: fitted to the particles' bounds)", kNonNegative);
        v.field("regir_lights_per_cell", regir_lights_per_cell, "render.source = regir: light reservoirs per cell (RTXDI LightsPerCell)", Range{1, 65536});
        v.field("regir_build_samples", regir_build_samples, "render.source = regir: tile candidates per cell reservoir, resampled by the cell's target (RTXDI regirNumBuildSamples)", Range{1, 1024});
        v.field("regir_jitter", regir_jitter, "render.source = regir: receiver position jitter in cells before the cell lookup (RTXDI regirSamplingJitter)", Range{0.0, 8.0});
        v.field("texels", texels, "particle_restir: texels per billboard side, each with its reservoirs (1, 2 or 4)", Range{1, 4});
        v.field("texel_rays", texel_rays, "particle_restir: independent reservoirs per texel, each traced with its own shadow ray (K)", Range{1, 16});
        v.field("pixel_shading", pixel_shading, "particle_restir: interpolate (bilinear over the particle's texels' Lr: biased) or resample (the pixel resamples its particle's texels' samples at its own point and traces its own shadow ray: unbiased)");
        v.field("texel_history", texel_history, "particle_restir with pixel_shading interpolate: a texel's Lr is (1 - h) x this frame's + h x its own last frame's, found by particle id (an exponential average: biased where the light changes)", Range{0.0, 0.99});
        v.field("world_neighbours", world_neighbours, "particle_restir: spatial reuse draws its neighbours among this many visible particles either side of the texel's in Morton order (world space)", Range{1, 1024});
    }
};

/// [voxel]: seed 004's voxel radiance cache (docs/MODEL.md section 4b,
/// docs/designs.md): a world-space grid over the particles whose cells hold
/// the light arriving at their centres, updated every frame from a ray
/// budget and read by the pixels by trilinear lookup.
struct VoxelSettings {
    std::uint32_t cells = 64;      ///< cells along the longest side of the particles' bounds
    std::uint32_t rays = 8;        ///< light samples (one shadow ray each) per occupied cell and frame
    double history = 16.0;         ///< frames a cell averages, at most (1: this frame's rays alone)
    VoxelBasis basis = VoxelBasis::l1; ///< the cell's directional basis
    double near_clamp = 0.0;       ///< a light nearer a cell's centre than this many cells counts as that far
    template <class V> void visit(V& v) {
        v.field("cells", cells, "voxel_cache: cells along the longest side of the particles' bounding box (cubic cells)", Range{1, 1024});
        v.field("rays", rays, "voxel_cache: lights drawn from render.source per occupied cell and frame, one shadow ray each from the cell's centre", Range{1, 1024});
        v.field("history", history, "voxel_cache: a cell's value is the mean of its last min(n, history) frames' (a running mean, then exponential with weight 1/history)", Range{1.0, 1e6});
        v.field("near_clamp", near_clamp, "voxel_cache: a light nearer a cell's centre than this many cells counts as that far (its 1/d^2 clamped there, as dmin clamps it), in the cells and in the own light taken out (0: the lights' own dmin only)", Range{0.0, 4.0});
        v.field("basis", basis, "voxel_cache: l1 (the incident light's L1 moments: any normal, the clamped cosine by its L1 convolution) or camera (the cosine lobe toward the camera from the cell's centre: billboards)");
    }
};

/// [particle_split]: seed 004's hybrid compute (docs/MODEL.md section 4b,
/// docs/designs.md): each visible particle's billboard texels lit by its
/// nearest lights summed exactly and far lights drawn from the light tree,
/// a shadow ray each; the pixels interpolate their particle's texels.
struct ParticleSplitSettings {
    std::uint32_t near = 16;       ///< nearest lights per particle, summed exactly
    std::uint32_t far = 8;         ///< far lights drawn per texel and frame
    std::uint32_t candidates = 1;  ///< far draws resampled into each far shadow ray
    std::uint32_t texels = 1;      ///< texels per billboard side
    double history = 0.0;          ///< weight of a texel's last Lr in its new one
    TexelPoint texel_point = TexelPoint::centre;  ///< where a texel's receiver lies on its billboard each frame
    HistoryOf history_of = HistoryOf::all;        ///< the terms the history averages
    HistoryStart history_start = HistoryStart::first;  ///< a new texel's average: from its first frame, or a running mean
    std::uint32_t far_new = 0;     ///< far draws of a texel without history (0: far)
    std::uint32_t far_prior = 0;   ///< far rays' worth of a new texel's near lights' far means (0: none)
    std::uint32_t far_share = 0;   ///< far rays' worth of every texel's near lights' far means in its Lr (0: none)
    bool far_handoff = false;      ///< the far history follows the near set's changes
    template <class V> void visit(V& v) {
        v.field("near", near, "particle_split: the lights nearest each visible particle's centre (on the light tree, no rays), summed exactly at each of its texels with a shadow ray each", Range{0, 64});
        v.field("far", far, "particle_split: lights drawn per texel and frame from the light tree at the texel, the near lights' ball taken out, one shadow ray each", Range{0, 1024});
        v.field("candidates", candidates, "particle_split: each far shadow ray's light is the one kept by RIS among this many far draws (the unshadowed term's luminance as target; 1: the draw itself)", Range{1, 256});
        v.field("texels", texels, "particle_split: texels per billboard side (1, 2, 3 or 4); the pixels interpolate them bilinearly", Range{1, 4});
        v.field("history", history, "particle_split: a texel's Lr is (1 - h) x this frame's + h x its own last frame's, found by particle id (an exponential average: biased where the light changes)", Range{0.0, 0.99});
        v.field("texel_point", texel_point, "particle_split: centre (a texel's receiver is its centre every frame), jittered (a point drawn afresh each frame, uniform in the texel's square of the billboard and inside the disc with alpha disc: with history the texel averages the light over the area its pixels see, not the light at its centre) or antithetic (such a point in even frames, its mirror about the texel's centre in the next: the pairs cancel the light's linear change across the texel)");
        v.field("history_of", history_of, "particle_split: all (the history averages the texel's whole Lr) or far (only the far lights' mean: the near sum, exact at the texel's point, is this frame's, so a long history lags the near light no more)");
        v.field("history_start", history_start, "particle_split: first (a texel's average starts at its first frame's value, which then weighs h^n after n frames) or mean (the mean of the n frames it has been seen until 1/n falls to 1 - h, then the exponential average: a particle that has just come into view is averaged as well as its frames allow)");
        v.field("far_new", far_new, "particle_split: far rays for a texel without history (its particle not in last frame's view: a history has nothing to average it with), at least far; 0: far. With history_start mean its age counts far rays, so that first frame weighs far_new / far frames", Range{0, 1024});
        v.field("far_prior", far_prior, "particle_split: with history_of far, a texel without history starts its far mean from the mean of its particle's near lights' far means of last frame (those then in view: its world-space neighbours' far light, biased by how theirs differs), weighted as this many far rays against its own; 0: its own rays alone", Range{0, 1024});
        v.field("far_share", far_share, "particle_split: with history_of far, every texel's Lr blends its far mean with the mean of its particle's near lights' far means of last frame (those then in view), theirs weighted as this many far rays and its own as its age in far rays (at most far (1 + h) / (1 - h)); its history keeps its own: a world-space filter of the far light, biased by how the neighbours' differs; 0: off", Range{0, 65536});
        v.field("far_handoff", far_handoff, "particle_split: with history_of far, a texel's far history follows its particle's near set: a light that joined it since last frame (in the history's far light, summed exactly now) is taken out of the history at its term now, one that left it (missing from the history, a far light now) put in at its term last frame (kept per texel); without it the history keeps the far light of the near sets it averaged, and a disk whose neighbours drift apart comes out dark");
    }
};

/// An SER sort key as the settings hold it: its components, most
/// significant first ("hit,type" in a scene file).
struct SerKeySpec {
    std::vector<SerComponent> components{SerComponent::hit, SerComponent::type};
    bool operator==(const SerKeySpec&) const = default;
};

/// The one parser of SER key text ("hit,type,cluster,hint", comma-separated,
/// no empty component): scene files, -D and `cost --ser-keys`. On an unknown
/// or empty component returns nothing and sets `bad` to it.
std::optional<SerKeySpec> parseSerKey(std::string_view text, std::string& bad);
/// "hit,type".
std::string formatSerKey(const SerKeySpec& key);

/// [gpu]: the GPU model (docs/MODEL.md section 6): counters, warps, SER, opacity
/// micromaps, memory estimates and the cost model's coefficients.
struct GpuSettings {
    bool counters = false;                    ///< record per-pass, per-pixel counters (costs time)
    std::uint32_t group_width = 8;            ///< thread group width
    std::uint32_t group_height = 8;           ///< thread group height
    std::uint32_t warp_size = 32;             ///< lanes per warp
    SerKeySpec ser_key;                       ///< SER sort key components, most significant first
    std::uint32_t ser_hint_bits = 0;          ///< coherence-hint bits appended to the SER key
    std::uint32_t ser_window = 2048;          ///< threads regrouped together (those an SM holds)
    double ser_reorder_cost = 0.25;           ///< reorder cost per thread, in lane-steps
    OmmMode omm = OmmMode::off;               ///< opacity micromaps on disc-alpha billboards
    std::uint32_t omm_level = 4;              ///< OMM subdivision level L (4^L micro-triangles per triangle)
    double blas_bytes_per_triangle = 48.0;    ///< GPU BLAS estimate: bytes per triangle (leaf data)
    double blas_bytes_per_node = 64.0;        ///< GPU BLAS estimate: bytes per internal node
    std::uint32_t bvh_width = 4;              ///< GPU BVH branching factor (internal nodes = (tris - 1) / (width - 1))
    double blas_compaction = 0.6;             ///< compacted / built BLAS size
    std::uint32_t blas_alignment = 65536;     ///< alignment of one allocation per BLAS
    std::uint32_t pool_alignment = 256;       ///< alignment of a BLAS in a pooled buffer
    std::string coefficients;                 ///< cost model coefficients (JSON from `accretion calibrate`); empty: defaults
    template <class V> void visit(V& v) {
        v.field("counters", counters, "record per-pass, per-pixel GPU counters (heatmap AOVs, stats)");
        v.field("group_width", group_width, "thread group width", Range{1, 64});
        v.field("group_height", group_height, "thread group height", Range{1, 64});
        v.field("warp_size", warp_size, "lanes per warp", Range{1, 128});
        v.field("ser_key", ser_key, "SER sort key: comma-separated hit, type, cluster, hint (most significant first)");
        v.field("ser_hint_bits", ser_hint_bits, "coherence-hint bits in the SER key", Range{0, 16});
        v.field("ser_window", ser_window, "threads regrouped together by SER", Range{1, 1 << 20});
        v.field("ser_reorder_cost", ser_reorder_cost, "SER cost per reordered thread, in lane-steps", kNonNegative);
        v.field("omm", omm, "opacity micromaps for disc alpha: off, 2state, 4state");
        v.field("omm_level", omm_level, "OMM subdivision level (0-6)", Range{0, 6});
        v.field("blas_bytes_per_triangle", blas_bytes_per_triangle, "GPU BLAS estimate: bytes per triangle", kNonNegative);
        v.field("blas_bytes_per_node", blas_bytes_per_node, "GPU BLAS estimate: bytes per internal node", kNonNegative);
        v.field("bvh_width", bvh_width, "GPU BVH branching factor", Range{2, 16});
        v.field("blas_compaction", blas_compaction, "compacted / built BLAS size", Range{0.0, 1.0, true});
        v.field("blas_alignment", blas_alignment, "alignment of one allocation per BLAS (bytes)", Range{1, 1 << 30});
        v.field("pool_alignment", pool_alignment, "alignment of a BLAS in a pooled buffer (bytes)", Range{1, 1 << 30});
        v.field("coefficients", coefficients, "cost model coefficients file (from accretion calibrate); empty: defaults");
    }
};

/// Every setting of a run, parsed and validated in one place (scene_parser).
struct Settings {
    ParticleSettings particles;
    CameraSettings camera;
    GeometrySettings geometry;
    ShadingSettings shading;
    RenderSettings render;
    RestirSettings restir;
    VoxelSettings voxel;
    ParticleSplitSettings particle_split;
    GpuSettings gpu;

    std::string sceneName = "scene"; ///< stem of the scene file
    std::string scenePath;           ///< scene file as given

    template <class V> void visit(V& v) {
        v.section("particles", particles);
        v.section("camera", camera);
        v.section("geometry", geometry);
        v.section("shading", shading);
        v.section("render", render);
        v.section("restir", restir);
        v.section("voxel", voxel);
        v.section("particle_split", particle_split);
        v.section("gpu", gpu);
    }
};

/// Output path of a frame: {scene} and {frame} (zero-padded to 4) replaced.
std::string expandPattern(std::string_view pattern, std::string_view scene, std::uint32_t frame);

}  // namespace accretion
