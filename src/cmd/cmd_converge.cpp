// accretion converge: error against time and against samples / rays, per
// estimator, on the same frame (or, with --sequence, per frame of an
// animated sequence), against a reference EXR.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include "accretion/analysis/experiment.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/analysis/view_check.h"
#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/version.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "accretion/io/stats_writer.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct ConvergeArgs : ExperimentArgs {
    ConvergeArgs() {
        estimators = "uniform,power,tree,split,ris,restir";
        seeds = 3;  // a point's time is the median of 3 renders: one render's timing noise bends curves back
    }
    std::string budget = "60s";
    std::uint32_t sequence = 0, minEffort = 1, maxEffort = 1u << 16;
};

double parseSeconds(const std::string& text) {
    std::string t = text;
    double scale = 1.0;
    if (t.size() > 1 && t.back() == 's') t.pop_back();
    else if (t.size() > 1 && t.back() == 'm') {
        t.pop_back();
        scale = 60.0;
    }
    const std::optional<double> v = parseNumber(t);
    if (!v || !(*v > 0.0)) throw InputError(fmt::format("command line --budget {}: expected a duration such as 60s or 2m", text));
    return *v * scale;
}

struct Point {
    std::string label;
    std::uint32_t frame = 0;
    std::uint32_t effort = 0;  ///< spp (MC), reservoirs (ris) or candidates (restir)
    double seconds = 0.0, totalSeconds = 0.0;
    std::uint64_t shadowRays = 0, lightTerms = 0;
    ErrorMetrics err;
    double flicker = NAN;          ///< --sequence: relMSE of the change from the previous frame against the reference's (mean over seeds)
    double referenceChange = NAN;  ///< and the reference sequence's own change
};

/// The baseline's time to reach an error, from the Monte Carlo rate
/// relMSE = c / t fitted to its whole curve (c = geometric mean of relMSE x t):
/// single renders' relMSE is heavy-tailed (fireflies), so interpolating
/// between two noisy points would be less reliable than the known rate.
double timeAtError(const std::vector<Point>& curve, double relMSE) {
    double logC = 0.0;
    std::size_t n = 0;
    for (const Point& p : curve) {
        const double e = p.err.relMSE - p.err.relMSEFloor;
        if (!(e > 0.0) || !(p.seconds > 0.0)) continue;
        logC += std::log(e * p.seconds);
        ++n;
    }
    if (n == 0 || !(relMSE > 0.0)) return NAN;
    return std::exp(logC / double(n)) / relMSE;
}

/// A reference image: Lr and, when it has one, its per-pixel standard error.
struct Reference {
    std::vector<Vec3> Lr, stderr;
    bool hasStderr = false;
};

/// The reference of `frame` (a {frame} pattern for --sequence), checked against the scene's resolution.
Reference loadReference(const std::string& pattern, const Settings& scene, std::uint32_t frame) {
    const std::string file = expandPattern(pattern, scene.sceneName, frame);
    const RgbLayer L = readExrLayer(file, "Lr");
    if (!L.whole())
        throw InputError(fmt::format("{}: a cropped reference (data window {}x{} at ({}, {})); converge measures whole images", file,
                                     L.dataWidth, L.dataHeight, L.x0, L.y0));
    if (L.width != scene.camera.width || L.height != scene.camera.height)
        throw InputError(fmt::format("{}: reference is {}x{}, the scene renders {}x{}", file, L.width, L.height,
                                     scene.camera.width, scene.camera.height));
    // Of the frame measured and the scene's settings; finite.
    requireSceneView(readExrAttributes(file), file, FileRole::reference, scene, frame, false);
    Reference r;
    r.Lr = L.rgb;
    requireFinitePixels(r.Lr, file, "Lr", L.width);
    if (exrHasLayer(file, "Lr_stderr")) {
        r.stderr = readExrLayer(file, "Lr_stderr").rgb;
        r.hasStderr = true;
        requireFinitePixels(r.stderr, file, "Lr_stderr", L.width);
    }
    return r;
}

/// One point's renders over the seeds: errors are their means, time per frame their median.
class SeedAverage {
public:
    SeedAverage(std::string label, std::uint32_t frame, std::uint32_t effort, std::uint32_t seeds)
        : seeds_(seeds) {
        p_.label = std::move(label);
        p_.frame = frame;
        p_.effort = effort;
    }
    void add(const std::vector<Vec3>& Lr, const Reference& ref, const FrameStats& stats, double frameSeconds,
             double totalSeconds) {
        const ErrorMetrics e = computeErrors(Lr, ref.Lr, ref.hasStderr ? &ref.stderr : nullptr);
        frameSeconds_.push_back(frameSeconds);
        p_.totalSeconds += totalSeconds;
        p_.shadowRays += stats.lighting.shadowRays;
        p_.lightTerms += stats.lighting.lightTerms;
        p_.err.relMSE += e.relMSE / seeds_;
        p_.err.MSE += e.MSE / seeds_;
        p_.err.MAPE += e.MAPE / seeds_;
        p_.err.relMSEFloor = e.relMSEFloor;
        p_.err.pixels = e.pixels;
    }
    Point finish() {
        std::sort(frameSeconds_.begin(), frameSeconds_.end());
        p_.seconds = frameSeconds_[frameSeconds_.size() / 2];
        p_.shadowRays /= seeds_;
        p_.lightTerms /= seeds_;
        return p_;
    }

private:
    Point p_;
    std::uint32_t seeds_;
    std::vector<double> frameSeconds_;
};

/// What every measurement reads.
struct ConvergeRun {
    const ConvergeArgs& a;
    const Settings& scene;
    const std::vector<FlagSetting>& base;  ///< --frames
    const ParticleSource& source;
    std::uint32_t frame;
    double budget;
};

/// --sequence: each estimator over N frames from one history per seed.
std::vector<Point> measureSequence(const ConvergeRun& run, const std::vector<EstimatorSpec>& specs) {
    const ConvergeArgs& a = run.a;
    std::vector<Reference> refs;
    for (std::uint32_t k = 0; k < a.sequence; ++k) refs.push_back(loadReference(a.reference(), run.scene, run.frame + k));
    std::vector<Point> points;
    for (const EstimatorSpec& spec : specs) {
        Settings s = specSettings(a.scene, a.defines, run.base, spec);
        // The history before the first measured frame, rendered and not measured.
        const std::uint32_t history = historyBefore(HistoryChoice::parse(a.history), s, run.frame, spec.label);
        s.render.frame_start = run.frame - history;
        s.render.frames = history + a.sequence;
        const std::uint64_t seed0 = s.render.seed;
        std::vector<SeedAverage> perFrame;
        for (std::uint32_t k = 0; k < a.sequence; ++k) perFrame.emplace_back(spec.label, run.frame + k, 0, a.seeds);
        std::vector<double> flicker(a.sequence, 0.0), change(a.sequence, 0.0);
        for (std::uint32_t seed = 0; seed < a.seeds; ++seed) {
            s.render.seed = seed0 + seed;
            FrameRenderer renderer(s, run.source, RenderOptions{true});
            for (std::uint32_t k = 0; k < history; ++k) {
                FrameStats stats;
                renderer.render(run.frame - history + k, stats);
            }
            std::vector<Vec3> previous;
            for (std::uint32_t k = 0; k < a.sequence; ++k) {
                FrameStats stats;
                FrameImage img = renderer.render(run.frame + k, stats);
                perFrame[k].add(img.lighting.Lr, refs[k], stats, stats.seconds, stats.seconds);
                if (k > 0) flicker[k] += flickerRelMse(img.lighting.Lr, previous, refs[k].Lr, refs[k - 1].Lr, &change[k]) / a.seeds;
                previous = std::move(img.lighting.Lr);
            }
        }
        for (std::uint32_t k = 0; k < a.sequence; ++k) {
            Point p = perFrame[k].finish();
            if (k > 0) {
                p.flicker = flicker[k];
                p.referenceChange = change[k];
            }
            if (!a.quiet)
                fmt::print(stderr, "converge: {} frame {}: {:.3f} s, relMSE {:.4g}, MAPE {:.4g}, flicker {:.4g}\n", spec.label,
                           p.frame, p.seconds, p.err.relMSE, p.err.MAPE, p.flicker);
            points.push_back(p);
        }
    }
    return points;
}

/// One frame: each estimator at doubling effort until its share of the budget is spent.
std::vector<Point> measureLevels(const ConvergeRun& run, const std::vector<EstimatorSpec>& specs) {
    const ConvergeArgs& a = run.a;
    const Reference ref = loadReference(a.reference(), run.scene, run.frame);
    std::vector<Point> points;
    for (const EstimatorSpec& spec : specs) {
        double spent = 0.0, last = 0.0;
        for (std::uint32_t effort = a.minEffort; effort <= a.maxEffort; effort *= 2) {
            if (spent > 0.0 && spent + 2.2 * last > run.budget) break;  // the next level would overrun the budget
            EstimatorSpec level = spec;
            const std::string flag = fmt::format("--min-effort/--max-effort (level {})", effort);
            const LightingPasses passes = estimatorInfo(spec.kind).passes;
            if (passes == LightingPasses::voxelCache)  // effort: the voxel cache's rays per cell
                level.settings.push_back({"voxel.rays", flag, [effort](Settings& st) { st.voxel.rays = effort; }});
            else if (passes == LightingPasses::particleSplit)  // effort: particle_split's far draws per texel
                level.settings.push_back({"particle_split.far", flag, [effort](Settings& st) { st.particle_split.far = effort; }});
            else if (estimatorInfo(spec.kind).reuse)  // effort: restir's candidates (one reservoir a pixel)
                level.settings.push_back({"render.candidates", flag, [effort](Settings& st) { st.render.candidates = effort; }});
            else
                level.settings.push_back({"render.samples", flag, [effort](Settings& st) { st.render.samples = effort; }});
            Settings s = specSettings(a.scene, a.defines, run.base, level);
            const std::uint32_t history = historyBefore(HistoryChoice::parse(a.history), s, run.frame, spec.label);
            SeedAverage avg(spec.label, run.frame, effort, a.seeds);
            const std::uint64_t seed0 = s.render.seed;
            for (std::uint32_t k = 0; k < a.seeds; ++k) {
                s.render.seed = seed0 + k;
                const ExperimentRender r = renderForExperiment(s, run.source, run.frame, history);
                avg.add(r.image.lighting.Lr, ref, r.stats, r.frameSeconds, r.totalSeconds);
            }
            const Point p = avg.finish();
            if (!a.quiet)
                fmt::print(stderr, "converge: {} x{}: {:.3f} s, relMSE {:.4g} (reference noise {:.3g})\n", spec.label,
                           effort, p.seconds, p.err.relMSE, p.err.relMSEFloor);
            points.push_back(p);
            spent += p.totalSeconds;
            last = p.totalSeconds;
            if (estimatorInfo(spec.kind).sums) break;  // no samples: one level
        }
    }
    return points;
}

/// Every point (the CSV).
Table pointsTable(const std::vector<Point>& points) {
    Table t({{"estimator"}, {"frame"}, {"effort"}, {"seconds", "", 0, "{}", "{:.6g}"}, {"total_seconds", "", 0, "{}", "{:.6g}"},
             {"shadow_rays"}, {"light_terms"}, {"relMSE", "", 0, "{}", "{:.8g}"}, {"MSE", "", 0, "{}", "{:.8g}"},
             {"MAPE", "", 0, "{}", "{:.8g}"}, {"relMSE_reference_noise", "", 0, "{}", "{:.8g}"},
             {"relMSE_corrected", "", 0, "{}", "{:.8g}"}, {"flicker", "", 0, "{}", "{:.8g}"},
             {"reference_change", "", 0, "{}", "{:.8g}"}});
    for (const Point& p : points)
        t.add({p.label, std::uint64_t(p.frame), std::uint64_t(p.effort), p.seconds, p.totalSeconds, p.shadowRays,
               p.lightTerms, p.err.relMSE, p.err.MSE, p.err.MAPE, p.err.relMSEFloor, p.err.relMSE - p.err.relMSEFloor,
               p.flicker, p.referenceChange});
    return t;
}

/// Each point with the time the baseline (the first Monte Carlo estimator
/// listed) needs for the same error (the console table and the JSON).
Table summaryTable(const std::vector<Point>& points, const std::vector<EstimatorSpec>& specs) {
    std::vector<Point> baseline;
    std::string baselineLabel;
    for (const EstimatorSpec& spec : specs)
        if (!estimatorInfo(spec.kind).sums && !estimatorInfo(spec.kind).resampling) {
            baselineLabel = spec.label;
            for (const Point& p : points)
                if (p.label == spec.label) baseline.push_back(p);
            break;
        }
    auto hidden = [](const char* key) { return Column{key, "", 0, "{}", "{}", false}; };
    Table t({{"estimator", "estimator", -28}, {"effort", "effort", 7}, {"seconds", "s/frame", 10, "{:.4f}"},
             {"relMSE", "relMSE", 12, "{:.5g}"},
             {"relMSE_corrected", "relMSE-noise", 12, "{:.5g}"}, hidden("MSE"), hidden("MAPE"), hidden("baseline"),
             hidden("baseline_seconds_at_equal_error"),
             {"speedup_at_equal_error", baselineLabel.empty() ? "" : "speed-up vs " + baselineLabel, 14, "{:.3g}"}});
    for (const EstimatorSpec& spec : specs)
        for (const Point& p : points) {
            if (p.label != spec.label) continue;
            const double corrected = p.err.relMSE - p.err.relMSEFloor;
            const double tBase = baseline.empty() || corrected <= 0.0 ? NAN : timeAtError(baseline, corrected);
            t.add({p.label, std::uint64_t(p.effort), p.seconds, p.err.relMSE, corrected, p.err.MSE, p.err.MAPE, baselineLabel,
                   tBase, tBase / p.seconds});
        }
    return t;
}

/// --sequence: relMSE (MAPE) and flicker at frames 0, 1, 3, 7, 15, ... of the sequence.
Table sequenceTable(const std::vector<Point>& points, const std::vector<EstimatorSpec>& specs, std::uint32_t frame,
                    std::uint32_t sequence) {
    std::vector<std::uint32_t> shown;
    for (std::uint32_t k = 1; k <= sequence; k *= 2) shown.push_back(k - 1);
    if (shown.back() != sequence - 1) shown.push_back(sequence - 1);
    std::vector<Column> columns{{"", "relMSE (MAPE) flicker at sequence frame", -44}};
    for (std::uint32_t k : shown) columns.push_back({"", std::to_string(k), 24});
    Table t(columns);
    for (const EstimatorSpec& spec : specs) {
        std::vector<Cell> row{spec.label};
        for (std::uint32_t k : shown)
            for (const Point& p : points)
                if (p.label == spec.label && p.frame == frame + k)
                    row.push_back(fmt::format("{:.3g} ({:.3f}) {:.3g}", p.err.relMSE, p.err.MAPE, p.flicker));
        t.add(row);
    }
    return t;
}

/// relMSE against time and against shadow rays (or against frame).
void plotConverge(const std::string& prefix, const std::vector<EstimatorSpec>& specs, bool sequence, const std::string& title) {
    std::string plots;
    for (const EstimatorSpec& spec : specs)
        plots += fmt::format("{}{} skip 1 using XCOL:(strcol(1) eq {} ? $8 : NaN) with linespoints title {}",
                             plots.empty() ? "" : ", ", gnuplotQuote(prefix + ".csv"), gnuplotQuote(spec.label),
                             gnuplotQuote(spec.label));
    auto withColumn = [&](const std::string& col) {
        std::string s = plots;
        for (std::size_t k; (k = s.find("XCOL")) != std::string::npos;) s.replace(k, 4, col);
        return s;
    };
    std::string script = "set datafile separator ','\nset key outside right\nset grid\nset ylabel 'relMSE'\nset logscale y\n";
    if (sequence) {
        script += "set title " + gnuplotQuote(title) + "\nset xlabel 'frame'\nplot " + withColumn("2") + "\n";
        plotPng(prefix + ".png", script);
        return;
    }
    script += "set multiplot layout 1,2 title " + gnuplotQuote(title) + "\nset logscale x\nset xlabel 'seconds per frame'\nplot " + withColumn("4") +
              "\nset xlabel 'shadow rays'\nplot " + withColumn("6") + "\nunset multiplot\n";
    plotPng(prefix + ".png", script, 1400, 600);
}

void runConverge(const ConvergeArgs& a) {
    const std::vector<FlagSetting> base = frameFlags(a.frames);
    const Settings scene = loadSceneArgs(a);
    requireWholeImage(scene, "converge");
    if (a.references.size() != 1)
        throw InputError(fmt::format("command line --reference: converge measures against one reference ({} given)", a.references.size()));
    const auto specs = parseEstimatorSpecs(a.estimators, "--estimators");
    const double budget = parseSeconds(a.budget);
    const std::uint32_t frame = a.frame.value_or(scene.render.frame_start);
    if (a.minEffort > a.maxEffort)
        throw InputError(fmt::format("command line --min-effort {} --max-effort {}: no effort to try (the range is empty)",
                                     a.minEffort, a.maxEffort));
    if (a.sequence > 0 && a.reference().find("{frame}") == std::string::npos)
        throw InputError(fmt::format("command line --reference {}: --sequence measures each frame against its own "
                                     "reference; give a {{frame}} pattern", a.reference()));
    if (std::uint64_t(frame) + a.sequence > 0xffffffffull)
        throw InputError(fmt::format("command line --frame {} --sequence {}: frames are 32-bit numbers (the last is "
                                     "4294967294)", frame, a.sequence));
    requireHistories(a, base, specs, frame);
    const auto threads = limitThreads(a.threads);
    const std::string prefix = a.out.empty() ? "out/" + scene.sceneName + ".converge" : a.out;
    OutputGuard guard = sceneInputs(scene);
    guard.addInput(a.reference());
    checkOutputs(guard, prefix, {".csv", ".png", ".json"}, "-o");

    const ParticleSource source(scene);
    const ConvergeRun run{a, scene, base, source, frame, budget};
    const std::vector<Point> points = a.sequence > 0 ? measureSequence(run, specs) : measureLevels(run, specs);
    // The folder once there is something to write: a refused reference leaves none.
    if (auto dir = std::filesystem::path(prefix).parent_path(); !dir.empty()) std::filesystem::create_directories(dir);
    writeFileAtomic(prefix + ".csv", pointsTable(points).csv());
    nlohmann::json summary = nlohmann::json::array();
    if (a.sequence == 0) {
        const Table t = summaryTable(points, specs);
        fmt::print("{}", t.console());
        summary = t.json();
    }
    writeJson(prefix + ".json", {{"version", std::string(version())},
                                 {"command", "converge"},
                                 {"scene", scene.scenePath},
                                 {"reference", a.reference()},
                                 {"frame", frame},
                                 {"budget_seconds", budget},
                                 {"history", a.history},
                                 {"seeds_per_point", a.seeds},
                                 {"speedup_model", "baseline relMSE = c / seconds, c fitted over its curve"},
                                 {"estimators", a.estimators},
                                 {"settings", settingsToToml(scene)},
                                 {"points", summary}});
    if (a.sequence > 0) fmt::print("{}", sequenceTable(points, specs, frame, a.sequence).console());
    plotConverge(prefix, specs, a.sequence > 0,
                 fmt::format("{} frame {}{}, {} seed{} per point", std::filesystem::path(scene.scenePath).filename().string(),
                             frame, a.sequence > 0 ? fmt::format(" (+{} frames)", a.sequence - 1) : std::string(), a.seeds,
                             a.seeds == 1 ? " (times of one render: give --seeds 3 or more for smooth curves)" : "s"));
    fmt::print("converge: {}.csv, {}.png, {}.json\n", prefix, prefix, prefix);
}

}  // namespace

void addConvergeCommand(CLI::App& app) {
    auto args = std::make_shared<ConvergeArgs>();
    CLI::App* cmd = app.add_subcommand("converge", "Error against time and rays per estimator, against a reference EXR");
    addExperimentOptions(cmd, *args, "Reference EXR with an Lr layer ({frame} pattern with --sequence)",
                         "Comma-separated specs name[:option...]: uniform, power, tree, split, ris[:power], "
                         "restir[:none|basic|basic+vis|pairwise], options key=value override settings",
                         "Output prefix (default out/<scene>.converge): .csv, .png, .json");
    cmd->add_option("--budget", args->budget, "Time budget per estimator (e.g. 60s, 2m)");
    cmd->add_option("--sequence", args->sequence, "Error per frame over N frames from --frame (one history per estimator)")
        ->check(unsignedNumber());
    cmd->add_option("--min-effort", args->minEffort, "First spp (restir: candidates) tried; doubled from there")
        ->check(unsignedNumber())
        ->check(CLI::Range(1u, 1u << 30));
    cmd->add_option("--max-effort", args->maxEffort, "Largest spp (restir: candidates) tried")
        ->check(unsignedNumber())
        ->check(CLI::Range(1u, 1u << 30));
    cmd->add_option("--seeds", args->seeds, "Renders per point (default 3): errors are their means, time their median")
        ->check(CLI::Range(1u, 100000u));
    cmd->footer("Effort doubles from --min-effort (spp; ris reservoirs; restir candidates) until the budget is spent.\n"
                "relMSE_corrected subtracts the reference's own noise (its Lr_stderr layer) in expectation.");
    cmd->callback([args] { runConverge(*args); });
}

}  // namespace accretion::cmd
