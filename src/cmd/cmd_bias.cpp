// accretion bias: per estimator, the mean signed error over many seeds with
// its standard error, the energy loss, and a per-pixel bias map, so a bias
// can be told apart from noise (docs/MODEL.md section 5).
#include <cmath>
#include <limits>
#include <filesystem>
#include <memory>
#include <optional>
#include <unordered_set>
#include <bit>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "accretion/analysis/bias_test.h"
#include "accretion/analysis/error_anatomy.h"
#include "accretion/analysis/experiment.h"
#include "accretion/analysis/student_t.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/analysis/view_check.h"
#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/progress.h"
#include "accretion/core/version.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/false_colour.h"
#include "accretion/io/gpu_frame_file.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "accretion/io/stats_writer.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/render/pixel_window.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct BiasArgs : ExperimentArgs {
    BiasArgs() {
        estimators = "ris,restir:none,restir:basic,restir:pairwise";
        seeds = 64;
    }
    double zCritical = 3.29;  ///< two-sided 99.9%
    std::string gpuFrames;    ///< read each seed's image from these .gpuframe files instead of rendering it
    bool strict = false;      ///< a view check that cannot be performed is an error
    std::vector<std::string> unshadowedReferences;  ///< the view with shading.visibility = false: the error without visibility
    std::uint32_t cropMargin = 32;  ///< restir on a cropped reference: the pixels around each crop it renders for its reuse
    std::uint32_t ageFrames = 0;    ///< --age-frames: the error by the frames each pixel's particle has been in view, up to this many before
};

struct BiasRow {
    std::string label;
    std::uint32_t seeds = 0;
    std::uint32_t history = 0;  ///< frames rendered before the measured one
    double meanError = 0.0;    ///< mean over seeds of the image-mean signed error (x - ref)
    double stderr = 0.0;       ///< its standard error (seeds and reference noise)
    double t = 0.0;            ///< meanError / stderr: Student's t with `dof` degrees of freedom
    double seedSd = 0.0;       ///< the seeds' sample standard deviation of the image-mean signed error
    double dof = 0.0;          ///< Welch-Satterthwaite's, from the seeds' spread and the reference's
    double critical = 0.0;     ///< the two-sided critical |t| at --z's significance
    double energyLossPct = 0.0;
    double secondsPerRender = 0.0;
    double secondsPerFrame = 0.0;  ///< the measured frame alone (restir: without its history frames)
    double relMse = 0.0;       ///< mean over seeds of one render's relMSE, less the reference's own noise
    double relMseStderr = NAN; ///< its standard error, from the seeds' spread (NaN for one seed)
    ErrorAnatomy anatomy;      ///< relMse as the per-pixel bias the seeds share and the noise they do not
    std::vector<ErrorAnatomy> byAge;  ///< --age-frames: the same by ParticleAges' groups
    bool biased = false;
    double detectablePct = 0.0;  ///< the smallest |energy bias| (%) this run detects with 80% probability
    PassReuse reuse;             ///< restir: the measured frames' reuse offers by outcome, summed over the seeds
    double relMseUnshadowed = NAN;  ///< --unshadowed-reference: relMSE of the same spec with every light visible
    std::vector<FloatChannel> map;  ///< the bias map, written once every estimator has been measured
    std::string settingsToml;       ///< the estimator's settings, recorded in its map
};

/// The reference: Lr over the pixels measured, the whole image or the crops
/// of it that the --reference files hold (each its EXR data window, at the
/// scene's resolution: a stratified set of crops measures the frame where
/// the engine runs it, never downscaled), crop after crop; their per-pixel
/// standard error when they have one, and the mean over those pixels.
struct BiasReference {
    std::uint32_t width = 0, height = 0;  ///< the image
    std::vector<PixelWindow> crops;       ///< the windows measured (the whole image: one, whole)
    std::vector<std::string> files;       ///< one per crop
    std::vector<Vec3> rgb;                ///< the crops' pixels, crop after crop, row by row
    std::vector<Vec3> stderr;             ///< the same; empty without Lr_stderr layers
    std::vector<std::uint32_t> ids;       ///< the same, particle.id; empty unless every file has one
    double mean = 0.0, meanStderr = 0.0;
    bool whole() const { return crops.size() == 1 && crops[0].isWhole(width, height); }
    /// A per-pixel layer of the crops' pixels as the whole image, 0 outside them.
    std::vector<float> scatter(const std::vector<float>& values) const {
        std::vector<float> image(std::size_t(width) * height, 0.0f);
        std::size_t k = 0;
        for (const PixelWindow& w : crops)
            for (std::uint32_t y = w.y0; y < w.y1; ++y)
                for (std::uint32_t x = w.x0; x < w.x1; ++x) image[std::size_t(y) * width + x] = values[k++];
        return image;
    }
};

/// One reference file's crop of the scene's view, checked.
PixelWindow referenceCrop(const RgbLayer& image, const std::string& file, const Settings& scene) {
    if (image.width != scene.camera.width || image.height != scene.camera.height)
        throw InputError(fmt::format("{}: reference is {}x{}, the scene renders {}x{}", file, image.width, image.height,
                                     scene.camera.width, scene.camera.height));
    if (image.x0 < 0 || image.y0 < 0 || std::uint64_t(image.x0) + image.dataWidth > image.width ||
        std::uint64_t(image.y0) + image.dataHeight > image.height || image.dataWidth == 0 || image.dataHeight == 0)
        throw InputError(fmt::format("{}: data window {}x{} at ({}, {}) is not a window of the {}x{} image", file, image.dataWidth,
                                     image.dataHeight, image.x0, image.y0, image.width, image.height));
    return {std::uint32_t(image.x0), std::uint32_t(image.x0) + image.dataWidth, std::uint32_t(image.y0),
            std::uint32_t(image.y0) + image.dataHeight};
}

/// The --reference files of one view: each of the scene's size and view
/// (its frame and scene-defining settings), the crops apart, all with an
/// Lr_stderr layer or none.
BiasReference loadBiasReference(const std::vector<std::string>& files, const Settings& scene, std::uint32_t frame, bool strict,
                                const char* option) {
    BiasReference r;
    r.width = scene.camera.width;
    r.height = scene.camera.height;
    for (const std::string& file : files) {
        const RgbLayer image = readExrLayer(file, "Lr");
        const PixelWindow crop = referenceCrop(image, file, scene);
        for (std::size_t k = 0; k < r.crops.size(); ++k) {
            const PixelWindow& o = r.crops[k];
            if (crop.x0 < o.x1 && o.x0 < crop.x1 && crop.y0 < o.y1 && o.y0 < crop.y1)
                throw InputError(fmt::format("command line {} {}: its pixels [{}, {}) x [{}, {}) overlap those of {}: a pixel is "
                                             "measured once", option, file, crop.x0, crop.x1, crop.y0, crop.y1, r.files[k]));
        }
        requireFinitePixels(image.rgb, file, "Lr", image.dataWidth);
        const bool hasStderr = exrHasLayer(file, "Lr_stderr");
        if (!r.files.empty() && hasStderr != !r.stderr.empty())
            throw InputError(fmt::format("command line {} {}: {} an Lr_stderr layer and {} {}: the references' noise is known for "
                                         "all of them or none", option, file, hasStderr ? "has" : "has no", r.files[0],
                                         hasStderr ? "has none" : "has one"));
        if (hasStderr) {
            const std::vector<Vec3> se = readExrLayer(file, "Lr_stderr").rgb;
            requireFinitePixels(se, file, "Lr_stderr", image.dataWidth);
            r.stderr.insert(r.stderr.end(), se.begin(), se.end());
        }
        requireSceneView(readExrAttributes(file), file, FileRole::reference, scene, frame, strict);
        const std::vector<std::uint32_t> ids = readExrUintChannel(file, "particle.id");
        if (!ids.empty() && r.ids.size() == r.rgb.size()) r.ids.insert(r.ids.end(), ids.begin(), ids.end());
        r.rgb.insert(r.rgb.end(), image.rgb.begin(), image.rgb.end());
        r.crops.push_back(crop);
        r.files.push_back(file);
    }
    const std::size_t pixels = r.rgb.size();
    if (r.ids.size() != pixels) r.ids.clear();
    const double n = 3.0 * double(pixels);
    double var = 0.0;
    for (std::size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            r.mean += r.rgb[p][c];
            if (!r.stderr.empty()) var += double(r.stderr[p][c]) * r.stderr[p][c];
        }
    r.mean /= n;
    r.meanStderr = std::sqrt(var) / n;  // independent pixels
    return r;
}

/// Per-pixel signed errors over the seeds: the bias map (mean signed error,
/// its standard error with the reference's, z of the luminance).
std::vector<FloatChannel> biasMap(const std::vector<DVec3>& s1, const std::vector<DVec3>& s2, double S, const BiasReference& ref) {
    const std::size_t pixels = s1.size();
    std::vector<FloatChannel> ch = {{"bias.R", {}}, {"bias.G", {}}, {"bias.B", {}},
                                    {"bias_stderr.R", {}}, {"bias_stderr.G", {}}, {"bias_stderr.B", {}}, {"bias_z.Y", {}}};
    for (auto& c : ch) c.values.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        const DVec3 m = s1[p] / S;
        const DVec3 var = glm::max((s2[p] / S - m * m) * (S / (S - 1.0)), DVec3(0.0));
        DVec3 se = glm::sqrt(var / S);
        if (!ref.stderr.empty()) se = glm::sqrt(se * se + DVec3(ref.stderr[p]) * DVec3(ref.stderr[p]));
        for (int c = 0; c < 3; ++c) {
            ch[c].values[p] = float(m[c]);
            ch[3 + c].values[p] = float(se[c]);
        }
        const double mY = luminance(Vec3(m)), seY = luminance(Vec3(se));
        ch[6].values[p] = seY > 0.0 ? float(mY / seY) : 0.0f;
    }
    return ch;
}

/// The <estimator> of prefix.<estimator>.exr: the spec's label, file-safe;
/// a label over 120 characters is cut to 100 and an FNV-1a hash of the
/// whole (a file name stays under the system's 255 bytes, and unique).
std::string biasMapName(const EstimatorSpec& spec) {
    std::string safe = spec.label;
    for (char& c : safe)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    if (safe.size() <= 120) return safe;
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : spec.label) h = (h ^ c) * 1099511628211ull;
    return fmt::format("{}_{:016x}", safe.substr(0, 100), h);
}

/// --gpu-frames: the pattern's {estimator} and {seed} filled in.
std::string gpuFramePath(std::string pattern, const std::string& estimator, std::uint64_t seed) {
    for (const auto& [key, value] : {std::pair<std::string, std::string>{"{estimator}", estimator}, {"{seed}", std::to_string(seed)}})
        for (std::size_t at; (at = pattern.find(key)) != std::string::npos;) pattern.replace(at, key.size(), value);
    return pattern;
}

/// Lr of seed `seed`'s frame as the OptiX twin rendered it (accretion-optix
/// --seeds), checked against what bias expects of it.
ExperimentRender readGpuRender(const std::string& file, const Settings& s, std::uint32_t frame, const BiasReference& ref,
                               bool strict) {
    GpuFrame g = readGpuFrame(file);
    auto meta = [&](const char* key) { return g.metadata.count(key) ? g.metadata.at(key) : std::string(); };
    if (g.width != ref.width || g.height != ref.height)
        throw InputError(fmt::format("{}: {}x{}, the reference is {}x{}", file, g.width, g.height, ref.width, ref.height));
    if (g.frame != frame) throw InputError(fmt::format("{}: frame {}, bias measures frame {}", file, g.frame, frame));
    if (meta("seed") != std::to_string(s.render.seed))
        throw InputError(fmt::format("{}: seed {}, expected {}", file, meta("seed"), s.render.seed));
    if (meta("estimator") != enumName(s.render.estimator))
        throw InputError(fmt::format("{}: estimator {}, expected {}", file, meta("estimator"), enumName(s.render.estimator)));
    // The scene the frame was rendered from (its metadata, as the EXR's attributes name it).
    std::map<std::string, std::string> attributes;
    for (const auto& [key, value] : g.metadata) attributes["accretion:" + key] = value;
    requireSceneView(attributes, file, FileRole::gpuFrame, s, frame, strict);
    requireFinitePixels(g.Lr, file, "Lr", g.width);
    ExperimentRender r;
    r.image.lighting.Lr = std::move(g.Lr);
    r.totalSeconds = parseNumber(meta("render_time_s")).value_or(0.0);
    return r;
}

/// Seeds first .. first + count - 1 of one spec over the reference's crops:
/// one lane per seed and crop (restir with --crop-margin around each crop:
/// restir.crop_margin) on each frame's geometry, built once for all of them
/// (renderLanesForExperiment). Each seed's Lr crop after crop (as ref.rgb),
/// its times and reuse summed over its crops.
std::vector<ExperimentRender> renderSeeds(const BiasArgs& a, const Settings& s, const ParticleSource& source, std::uint32_t frame,
                                          std::uint32_t history, const BiasReference& ref, std::uint32_t first, std::uint32_t count) {
    std::vector<Settings> lanes;
    for (std::uint32_t k = 0; k < count; ++k) {
        Settings seed = s;
        seed.render.seed = s.render.seed + first + k;
        if (ref.whole()) lanes.push_back(seed);
        for (const PixelWindow& w : ref.whole() ? std::vector<PixelWindow>{} : ref.crops) {
            Settings c = seed;
            c.render.crop = {double(w.x0), double(w.x1), double(w.y0), double(w.y1)};
            if (estimatorInfo(c.render.estimator).reuse) c.restir.crop_margin = a.cropMargin;
            lanes.push_back(std::move(c));
        }
    }
    const std::size_t perSeed = lanes.size() / count;
    std::vector<ExperimentRender> rendered = renderLanesForExperiment(std::move(lanes), source, frame, history);
    std::vector<ExperimentRender> seeds(count);
    for (std::uint32_t k = 0; k < count; ++k) {
        ExperimentRender& all = seeds[k];
        all.image.lighting.Lr.reserve(ref.rgb.size());
        for (std::size_t c = 0; c < perSeed; ++c) {
            ExperimentRender& r = rendered[k * perSeed + c];
            const std::vector<Vec3>& lr = r.image.lighting.Lr;
            all.image.lighting.Lr.insert(all.image.lighting.Lr.end(), lr.begin(), lr.end());
            all.frameSeconds += r.frameSeconds;
            all.totalSeconds += r.totalSeconds;
            for (const auto& [pass, counts] : r.stats.reuse) all.stats.reuse[pass] += counts;
        }
    }
    return seeds;
}

/// How many seeds render side by side: their lanes' pixels (each crop with
/// its margin, or the whole image) up to about four 1080p frames, whose
/// restir histories they keep.
std::uint32_t seedsPerBatch(const BiasArgs& a, const BiasReference& ref) {
    constexpr double kLanePixels = 4.0 * 1920.0 * 1080.0;
    double perSeed = 0.0;
    const double image = double(ref.width) * ref.height;
    for (const PixelWindow& w : ref.crops)
        perSeed += std::min(image, double(w.width() + 2 * a.cropMargin + 16) * double(w.height() + 2 * a.cropMargin + 16));
    return static_cast<std::uint32_t>(std::clamp(std::floor(kLanePixels / std::max(perSeed, 1.0)), 1.0, double(a.seeds)));
}

/// --age-frames N: each measured pixel's group by its particle's age, the
/// frames it has been in view (anywhere in the whole frame, this one
/// included: a texel history by particle id has as many): 1, 2-3, 4-7, ...
/// up to N, then "more than N" (in view in each of the N frames before);
/// pixels that see no particle apart. Texel designs' noise is largest in
/// particles new to the view, whose history is short.
struct ParticleAges {
    std::vector<std::string> labels;   ///< per group
    std::vector<std::uint32_t> group;  ///< per measured pixel (as ref.rgb)
    std::vector<std::size_t> pixels;   ///< per group
    std::uint32_t groups() const { return std::uint32_t(labels.size()); }
};

ParticleAges particleAges(const Settings& scene, const ParticleSource& source, std::uint32_t frame, std::uint32_t n,
                          const BiasReference& ref, bool quiet) {
    // The frames' views alone: one cheap light sample a pixel, no shadow rays; only the particle ids are read.
    Settings s = scene;
    s.render.estimator = EstimatorKind::uniform;
    s.render.samples = 1;
    s.render.crop = {};
    s.shading.visibility = false;
    FrameRenderer renderer(s, source, RenderOptions{true});
    std::vector<std::unordered_set<std::uint32_t>> seen;  // frames frame - n .. frame - 1
    std::vector<std::uint32_t> now;
    Progress progress("bias --age-frames (the particles in view)", n + 1, quiet);
    for (std::uint32_t f = frame - n; f <= frame; ++f) {
        FrameStats stats;
        FrameImage img = renderer.render(f, stats);
        if (f < frame) seen.emplace_back(img.particle.begin(), img.particle.end());
        else now = std::move(img.particle);
        progress.advance(1);
    }
    progress.finish();
    ParticleAges ages;
    ages.labels = {"no particle"};
    for (std::uint32_t lo = 1; lo <= n; lo *= 2)
        ages.labels.push_back(lo == std::min(2 * lo - 1, n) ? std::to_string(lo) : fmt::format("{}-{}", lo, std::min(2 * lo - 1, n)));
    ages.labels.push_back(fmt::format("more than {}", n));
    auto groupOf = [&](std::uint32_t age) -> std::uint32_t {
        if (age == 0) return 0;
        if (age > n) return ages.groups() - 1;
        return 1 + std::uint32_t(std::bit_width(age) - 1);
    };
    ages.pixels.assign(ages.groups(), 0);
    for (const PixelWindow& w : ref.crops)
        for (std::uint32_t y = w.y0; y < w.y1; ++y)
            for (std::uint32_t x = w.x0; x < w.x1; ++x) {
                const std::uint32_t id = now[std::size_t(y) * ref.width + x];
                std::uint32_t age = 0;
                if (id != kNoParticle)
                    for (age = 1; age <= n && seen[n - age].count(id); ++age) {}
                ages.group.push_back(groupOf(age));
                ++ages.pixels[ages.group.back()];
            }
    return ages;
}

/// One estimator over the seeds: its row, and its bias map at prefix.<estimator>.exr.
BiasRow measureBias(const BiasArgs& a, const EstimatorSpec& spec, const std::vector<FlagSetting>& base,
                    const ParticleSource& source, std::uint32_t frame, const BiasReference& ref, const std::string& prefix,
                    const ParticleAges* ages = nullptr) {
    const Settings specBase = specSettings(a.scene, a.defines, base, spec);
    const std::uint32_t history = historyBefore(HistoryChoice::parse(a.history), specBase, frame, spec.label);
    const std::size_t pixels = ref.rgb.size();
    const double n = 3.0 * double(pixels);
    std::vector<DVec3> s1(pixels, DVec3(0.0)), s2(pixels, DVec3(0.0));
    double e1 = 0.0, e2 = 0.0, seconds = 0.0, frameSeconds = 0.0, relMse = 0.0, relMse2 = 0.0;
    PassReuse reuse;
    Progress progress("bias " + spec.label + " (seeds)", a.seeds, a.quiet);
    auto add = [&](const ExperimentRender& r) {
        seconds += r.totalSeconds;
        for (const auto& [pass, counts] : r.stats.reuse) reuse[pass] += counts;
        frameSeconds += a.gpuFrames.empty() ? r.frameSeconds : r.totalSeconds;
        double e = 0.0;
        for (std::size_t p = 0; p < pixels; ++p) {
            const DVec3 d = DVec3(r.image.lighting.Lr[p]) - DVec3(ref.rgb[p]);
            s1[p] += d;
            s2[p] += d * d;
            e += d.x + d.y + d.z;
        }
        e /= n;
        const ErrorMetrics m = computeErrors(r.image.lighting.Lr, ref.rgb, ref.stderr.empty() ? nullptr : &ref.stderr);
        relMse += m.relMSE - m.relMSEFloor;
        relMse2 += (m.relMSE - m.relMSEFloor) * (m.relMSE - m.relMSEFloor);
        e1 += e;
        e2 += e * e;
        progress.advance(1);
    };
    if (!a.gpuFrames.empty()) {
        for (std::uint32_t k = 0; k < a.seeds; ++k) {
            Settings s = specBase;
            s.render.seed = specBase.render.seed + k;
            add(readGpuRender(gpuFramePath(a.gpuFrames, biasMapName(spec), s.render.seed), s, frame, ref, a.strict));
        }
    } else {
        const std::uint32_t batch = seedsPerBatch(a, ref);
        for (std::uint32_t k = 0; k < a.seeds; k += batch)
            for (const ExperimentRender& r : renderSeeds(a, specBase, source, frame, history, ref, k, std::min(batch, a.seeds - k)))
                add(r);
    }
    progress.finish();
    const double S = a.seeds;
    BiasRow row;
    row.label = spec.label;
    row.seeds = a.seeds;
    row.history = history;
    row.meanError = e1 / S;
    row.seedSd = std::sqrt(std::max(0.0, (e2 / S - row.meanError * row.meanError) * S / (S - 1.0)));
    const BiasTest test = biasTest(row.seedSd, a.seeds, ref.meanStderr, a.zCritical);
    row.stderr = test.stderr;
    row.dof = test.dof;
    row.critical = test.critical;
    // No spread at all (a deterministic estimator against an exact
    // reference): any difference beyond float summation is a bias, not noise.
    const double tiny = 1e-6 * std::max(std::fabs(ref.mean), 1e-30);
    row.t = row.stderr > 0.0 ? row.meanError / row.stderr
          : std::fabs(row.meanError) > tiny ? std::copysign(std::numeric_limits<double>::infinity(), row.meanError)
                                            : 0.0;
    row.energyLossPct = ref.mean > 0.0 ? -100.0 * row.meanError / ref.mean : 0.0;
    row.secondsPerRender = seconds / S;
    row.relMse = relMse / S;
    // A render's relMSE is heavy-tailed where rare bright samples land: its
    // mean over a few seeds can move by a quarter (1M particles, 4 seeds).
    if (a.seeds > 1) row.relMseStderr = std::sqrt(std::max(0.0, relMse2 / S - row.relMse * row.relMse) / (S - 1.0));
    row.secondsPerFrame = frameSeconds / S;
    row.biased = std::fabs(row.t) > row.critical;
    row.detectablePct = ref.mean > 0.0 ? 100.0 * test.detectable / ref.mean : std::numeric_limits<double>::infinity();
    row.anatomy = splitRelMse(s1, s2, S, ref.rgb, ref.stderr, kRelMseEpsilon);
    if (ages) row.byAge = splitRelMseByGroup(s1, s2, S, ref.rgb, ref.stderr, kRelMseEpsilon, ages->group, ages->groups());
    row.map = biasMap(s1, s2, S, ref);
    row.reuse = std::move(reuse);
    row.settingsToml = settingsToToml(specBase);
    return row;
}

/// One pass's reuse in words: "spatialResampling: 21% of 130690 kept (100%
/// on another particle); refused: 2% off_screen, 54% miss, 22% depth".
std::string reuseLine(Pass pass, const ReuseCounts& c) {
    const double offered = double(c.offered());
    auto pct = [&](std::uint64_t n, double of) { return of > 0.0 ? 100.0 * double(n) / of : 0.0; };
    std::string line = fmt::format("{}: {:.0f}% of {} kept", passName(pass), pct(c.accepted(), offered), c.offered());
    if (const std::uint64_t other = c.n[std::size_t(ReuseOutcome::otherParticle)])
        line += fmt::format(" ({:.0f}% on another particle)", pct(other, double(c.accepted())));
    std::string refused;
    for (std::size_t k = 0; k < kReuseOutcomes; ++k)
        if (!kept(ReuseOutcome(k)) && c.n[k])
            refused += fmt::format("{}{:.0f}% {}", refused.empty() ? "" : ", ", pct(c.n[k], offered), kReuseOutcomeNames[k]);
    if (!refused.empty()) line += "; refused: " + refused;
    if (c.mCapped) line += fmt::format("; M cap bound {:.0f}% of kept", pct(c.mCapped, double(c.accepted())));
    return line;
}

/// The rows as the console, CSV and JSON give them.
Table biasTable(const std::vector<BiasRow>& rows, double refMean, double zCritical) {
    const double significance = 1.0 - 2.0 * (1.0 - normalCdf(zCritical));
    auto hidden = [](const char* key, const char* csv) { return Column{key, "", 0, "{}", csv, false}; };
    Table t({{"estimator", "estimator", -28}, {"seeds", "seeds", 6}, {"history_frames", "hist", 5}, {"mean_signed_error", "mean error", 13, "{:.5g}", "{:.8g}"},
             {"stderr", "stderr", 11, "{:.3g}", "{:.8g}"}, {"t", "t", 8, "{:.2f}", "{:.5g}"},
             hidden("seed_sd", "{:.8g}"), {"dof", "dof", 6, "{:.3g}", "{:.6g}"}, {"t_critical", "|t| >", 6, "{:.2f}", "{:.6g}"},
             hidden("energy_loss_pct", "{:.6g}"), hidden("energy_loss_stderr_pct", "{:.6g}"), {"", "energy loss %", 15},
             hidden("biased", "{}"), hidden("detectable_bias_pct", "{:.4g}"), {"seconds_per_render", "s/render", 9, "{:.3f}", "{:.6g}"},
             {"seconds_per_frame", "s/frame", 8, "{:.3f}", "{:.6g}"}, {"rel_mse", "relMSE", 10, "{:.4g}", "{:.6g}"},
             {"rel_mse_stderr", "+-", 8, "{:.2g}", "{:.6g}"}, {"rel_mse_persistent", "persistent", 11, "{:.4g}", "{:.6g}"},
             {"rel_mse_noise", "noise", 10, "{:.4g}", "{:.6g}"}, {"rel_mse_unshadowed", "unshadowed", 11, "{:.4g}", "{:.6g}"}, {"visibility_share_pct", "vis share%", 11, "{:.0f}", "{:.4g}"},
             {"light_selection_share_pct", "sel share%", 11, "{:.0f}", "{:.4g}"},
             {"", fmt::format("verdict (|t| above its critical value, {:.3g}% two-sided)", 100.0 * significance), 0, "{}", "{}", true, "  "}});
    for (const BiasRow& r : rows) {
        const double lossSe = refMean > 0.0 ? 100.0 * r.stderr / refMean : 0.0;
        t.add({r.label, std::uint64_t(r.seeds), std::uint64_t(r.history), r.meanError, r.stderr, r.t, r.seedSd, r.dof, r.critical,
               r.energyLossPct, lossSe,
               fmt::format("{:>8.3f} +- {:<5.3f}", r.energyLossPct, lossSe), r.biased, r.detectablePct, r.secondsPerRender,
               r.secondsPerFrame, r.relMse, r.relMseStderr, r.anatomy.persistent, r.anatomy.noise, r.relMseUnshadowed, 100.0 * (r.relMse - r.relMseUnshadowed) / r.relMse,
               100.0 * r.relMseUnshadowed / r.relMse,
               r.biased ? "BIASED"
                        : fmt::format("no bias detected (a bias of {:.2g}% or more would show 4 times in 5)", r.detectablePct)});
    }
    return t;
}

/// --unshadowed-reference, for the anatomy of the error: each spec again
/// with every light visible (`flags` gains shading.visibility = false),
/// against a reference without visibility; what is left is light selection's.
std::optional<BiasReference> loadUnshadowedReference(const BiasArgs& a, std::vector<FlagSetting>& flags, std::uint32_t frame,
                                                     const BiasReference& shadowed) {
    if (a.unshadowedReferences.empty()) return std::nullopt;
    if (!a.gpuFrames.empty())
        throw InputError("command line --unshadowed-reference: not with --gpu-frames (the GPU frames are of one visibility)");
    flags.push_back({"shading.visibility", "--unshadowed-reference", [](Settings& s) { s.shading.visibility = false; }});
    const Settings unshadowedScene = loadSceneArgs(a, flags);
    BiasReference ref = loadBiasReference(a.unshadowedReferences, unshadowedScene, frame, a.strict, "--unshadowed-reference");
    if (ref.crops != shadowed.crops)
        throw InputError(fmt::format("command line --unshadowed-reference {}: its crops are not --reference's, in order (each "
                                     "visibility-free reference is the same window as its reference)",
                                     a.unshadowedReferences[0]));
    return ref;
}

void runBias(const BiasArgs& a) {
    const std::vector<FlagSetting> base = frameFlags(a.frames);
    const Settings scene = loadSceneArgs(a);
    requireWholeImage(scene, "bias");
    const auto specs = parseEstimatorSpecs(a.estimators, "--estimators");
    if (a.seeds < 2) throw InputError("command line --seeds: at least 2 seeds are needed for a standard error");
    const std::uint32_t frame = a.frame.value_or(scene.render.frame_start);
    requireHistories(a, base, specs, frame);
    if (a.ageFrames > frame)
        throw InputError(fmt::format("command line --age-frames {}: frame {} has only {} frames before it", a.ageFrames, frame, frame));
    if (a.ageFrames > 0 && !a.gpuFrames.empty())
        throw InputError("command line --age-frames: not with --gpu-frames (it renders the frames' views)");
    const auto threads = limitThreads(a.threads);
    const std::string prefix = a.out.empty() ? "out/" + scene.sceneName + ".bias" : a.out;
    OutputGuard guard = sceneInputs(scene);
    for (const std::string& r : a.references) guard.addInput(r);
    for (const std::string& r : a.unshadowedReferences) guard.addInput(r);
    std::vector<std::string> suffixes = {".csv", ".png", ".json"};
    for (const EstimatorSpec& spec : specs)
        for (const char* ext : {".exr", ".z.png"}) suffixes.push_back("." + biasMapName(spec) + ext);
    checkOutputs(guard, prefix, suffixes, "-o");

    // The references must be of the view measured: its frame and scene-defining settings.
    const BiasReference ref = loadBiasReference(a.references, scene, frame, a.strict, "--reference");
    if (!ref.whole() && !a.gpuFrames.empty())
        throw InputError(fmt::format("command line --gpu-frames: the GPU frames are whole frames, {} is a crop", a.references[0]));
    std::vector<FlagSetting> unshadowed = base;
    const std::optional<BiasReference> refUnshadowed = loadUnshadowedReference(a, unshadowed, frame, ref);
    const ParticleSource source(scene);
    std::optional<ParticleAges> ages;
    if (a.ageFrames > 0) ages = particleAges(scene, source, frame, a.ageFrames, ref, a.quiet);
    std::vector<BiasRow> rows;
    for (const EstimatorSpec& spec : specs) {
        rows.push_back(measureBias(a, spec, base, source, frame, ref, prefix, ages ? &*ages : nullptr));
        if (refUnshadowed) rows.back().relMseUnshadowed = measureBias(a, spec, unshadowed, source, frame, *refUnshadowed, prefix).relMse;
    }

    // Every output once every estimator has been measured: a failure leaves none.
    if (auto dir = std::filesystem::path(prefix).parent_path(); !dir.empty()) std::filesystem::create_directories(dir);
    for (std::size_t k = 0; k < rows.size(); ++k) {
        const std::string map = prefix + "." + biasMapName(specs[k]);
        std::vector<FloatChannel> channels = rows[k].map;
        for (FloatChannel& c : channels) c.values = ref.scatter(c.values);
        writeChannelsExr(map + ".exr", ref.width, ref.height, channels,
                         {{"version", std::string(version())}, {"estimator", rows[k].label},
                          {"seeds", std::to_string(a.seeds)}, {"reference", fmt::format("{}", fmt::join(a.references, " "))},
                          {"frame", std::to_string(frame)},
                          {"settings", rows[k].settingsToml},
                          {"renderer", a.gpuFrames.empty() ? "accretion" : "accretion-optix (" + a.gpuFrames + ")"}});
        const std::vector<float>& z = channels.back().values;
        writeFalseColourPng(map + ".z.png", z, ref.width, ref.height,
                            {-2.0 * a.zCritical, 2.0 * a.zCritical, true,
                             fmt::format("{}: bias z per pixel (luminance), {} seeds", rows[k].label, a.seeds)});
    }

    const Table table = biasTable(rows, ref.mean, a.zCritical);
    fmt::print("{}", table.console());
    // What no design that shades one value a particle can go below: the
    // references' own particle.id says which pixels share a particle.
    nlohmann::json floorJson;
    if (!ref.ids.empty()) {
        const ParticleMeanFloor f = particleMeanFloor(ref.rgb, ref.ids, ref.stderr, kRelMseEpsilon);
        fmt::print("one value a particle (each pixel its particle's mean reference Lr over the pixels measured): relMSE floor {:.4g}, "
                   "{} particles, a median {:g} pixels each\n", f.relMSE, f.particles, f.medianPixels);
        floorJson = {{"rel_mse", f.relMSE}, {"particles", f.particles}, {"median_pixels", f.medianPixels}};
    }
    nlohmann::json reuse = nlohmann::json::object();
    for (const BiasRow& r : rows) {
        if (r.reuse.empty()) continue;
        fmt::print("reuse of {} (the measured frames, {} seeds):\n", r.label, r.seeds);
        for (const auto& [pass, counts] : r.reuse) {
            fmt::print("  {}\n", reuseLine(pass, counts));
            reuse[r.label][std::string(passName(pass))] = reuseCountsJson(counts);
        }
    }
    nlohmann::json byAge;
    if (ages) {
        const std::size_t all = ages->group.size();
        for (const BiasRow& r : rows) {
            fmt::print("{}: relMSE by the frames its pixels' particle has been in view (this one included):\n", r.label);
            nlohmann::json groups = nlohmann::json::array();
            for (std::uint32_t g = 0; g < ages->groups(); ++g) {
                const ErrorAnatomy& e = r.byAge[g];
                const double share = r.relMse != 0.0 ? 100.0 * (e.noise + e.persistent) / r.relMse : 0.0;
                fmt::print("  {:>12}: {:5.1f}% of the pixels, relMSE {:.4g} ({:.0f}% of it): noise {:.4g}, persistent {:.4g}\n",
                           ages->labels[g], 100.0 * double(ages->pixels[g]) / double(all), e.noise + e.persistent, share, e.noise,
                           e.persistent);
                groups.push_back({{"frames_in_view", ages->labels[g]}, {"pixels", ages->pixels[g]},
                                  {"rel_mse_noise", e.noise}, {"rel_mse_persistent", e.persistent}});
            }
            byAge[r.label] = groups;
        }
    }
    writeFileAtomic(prefix + ".csv", table.csv());
    writeJson(prefix + ".json", {{"version", std::string(version())}, {"command", "bias"},
                                 {"scene", scene.scenePath}, {"reference", a.references}, {"crops", windowsJson(ref.crops)},
                                 {"crop_margin", ref.whole() ? nlohmann::json() : nlohmann::json(a.cropMargin)},
                                 {"frame", frame}, {"history", a.history}, {"z_critical", a.zCritical},
                                 {"reference_mean", ref.mean}, {"reference_mean_stderr", ref.meanStderr},
                                 {"particle_mean_floor", floorJson}, {"age_frames", a.ageFrames}, {"by_age", byAge},
                                 {"settings", settingsToToml(scene)}, {"rows", table.json()}, {"reuse", reuse}});
    // Red bars: BIASED (|t| above its critical value); the title says what was measured.
    const std::size_t biased = table.csvColumn("biased"), loss = table.csvColumn("energy_loss_pct"),
                      lossSe = table.csvColumn("energy_loss_stderr_pct"), critical = table.csvColumn("t_critical");
    const std::string script = fmt::format(
        "set datafile separator ','\nset style fill solid 0.5\nset boxwidth 0.6\nset grid ytics\n"
        "set title {1}\nset ylabel 'energy loss % (bars: the critical |t| in standard errors)'\nset xtics rotate by -30\nset key off\n"
        "plot {0} skip 1 using 0:(${2} == 1 ? NaN : ${3}):xtic(1) with boxes lc rgb '#4682b4', "
        "{0} skip 1 using 0:(${2} == 1 ? ${3} : NaN) with boxes lc rgb '#d62728', "
        "{0} skip 1 using 0:{3}:(${4}*${5}) with yerrorbars lc rgb 'black' pt 0\n",
        gnuplotQuote(prefix + ".csv"),
        gnuplotQuote(fmt::format("bias of {} frame {}, {} seeds (red: BIASED, |t| above its critical value)",
                                 std::filesystem::path(scene.scenePath).filename().string(), frame, a.seeds)),
        biased, loss, lossSe, critical);
    plotPng(prefix + ".png", script);
    fmt::print("bias: {}.csv, {}.png, {}.json, bias maps {}.<estimator>.exr (.z.png)\n", prefix, prefix, prefix, prefix);
}

}  // namespace

void addBiasCommand(CLI::App& app) {
    auto args = std::make_shared<BiasArgs>();
    CLI::App* cmd = app.add_subcommand("bias", "Mean signed error over many seeds per estimator, with its standard error");
    addExperimentOptions(cmd, *args, "Reference EXR with an Lr layer (and Lr_stderr if noisy): the whole view, or given once per crop, "
                         "crops of it (each its data window, at the scene's resolution), measured together",
                         "Comma-separated specs, as for converge",
                         "Output prefix (default out/<scene>.bias): .csv, .png, .json, bias-map EXRs");
    cmd->add_option("--seeds", args->seeds, "Independent renders per estimator")->check(CLI::Range(2u, 1000000u));
    cmd->add_flag("--strict", args->strict,
                  "A view check that cannot be made (a reference or GPU frame without accretion's metadata) is an error");
    cmd->add_option("--crop-margin", args->cropMargin,
                    "With cropped references: the pixels around each crop that restir renders for its reuse (restir.crop_margin)")
        ->check(CLI::Range(0u, 16384u));
    cmd->add_option("--unshadowed-reference", args->unshadowedReferences,
                    "The same view rendered with shading.visibility=false: each spec is measured again with every light "
                    "visible against it; its relMSE is light selection's error, the rest visibility's share (one per --reference, "
                    "the same crops)")
        ->allow_extra_args(false);
    cmd->add_option("--age-frames", args->ageFrames,
                    "Split each spec's relMSE (noise and persistent) by the frames its pixels' particle has been in view, up to "
                    "this many before the measured one: a texel history by particle id is as long (renders the frames' views)")
        ->check(CLI::Range(0u, 4096u));
    cmd->add_option("--z", args->zCritical, "The verdict's significance, as the normal's two-sided critical |z| (3.29: 99.9%); the test keeps it with Student's t at the seeds' degrees of freedom")->check(finiteIn(0.0, 1e6));
    cmd->add_option("--gpu-frames", args->gpuFrames,
                    "Read each seed's frame from the OptiX twin's .gpuframe files instead of rendering it: a pattern "
                    "with {estimator} (the spec, file-safe) and {seed} (render.seed + k)");
    cmd->callback([args] { runBias(*args); });
}

}  // namespace accretion::cmd
