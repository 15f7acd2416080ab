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
#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/version.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/plot.h"
#include "accretion/io/stats_writer.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct ConvergeArgs : SceneArgs {
    std::string reference, estimators = "uniform,power,tree,ris,restir", budget = "60s", out;
    std::uint32_t history = 8, sequence = 0, minEffort = 1, maxEffort = 1u << 16, seeds = 1;
    std::optional<std::uint32_t> frame;
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

void runConverge(const ConvergeArgs& a) {
    const std::vector<FlagSetting> base = frameFlags(a.frames);
    const Settings sceneSettings = loadSceneArgs(a);
    const auto specs = parseEstimatorSpecs(a.estimators, "--estimators");
    const double budget = parseSeconds(a.budget);
    const std::uint32_t frame = a.frame.value_or(sceneSettings.render.frame_start);
    const auto threads = limitThreads(a.threads);

    const std::string prefix = a.out.empty() ? "out/" + sceneSettings.sceneName + ".converge" : a.out;
    if (auto dir = std::filesystem::path(prefix).parent_path(); !dir.empty()) std::filesystem::create_directories(dir);

    // References: one file, or a {frame} pattern for --sequence.
    struct Ref {
        std::vector<Vec3> Lr, stderr;
        bool hasStderr = false;
    };
    auto loadRef = [&](std::uint32_t f) {
        const std::string file = expandPattern(a.reference, sceneSettings.sceneName, f);
        Ref r;
        const RgbLayer L = readExrLayer(file, "Lr");
        if (L.width != sceneSettings.camera.width || L.height != sceneSettings.camera.height)
            throw InputError(fmt::format("{}: reference is {}x{}, the scene renders {}x{}", file, L.width, L.height,
                                         sceneSettings.camera.width, sceneSettings.camera.height));
        r.Lr = L.rgb;
        if (exrHasLayer(file, "Lr_stderr")) {
            r.stderr = readExrLayer(file, "Lr_stderr").rgb;
            r.hasStderr = true;
        }
        return r;
    };

    std::vector<Point> points;
    const ParticleSource source(sceneSettings);
    if (a.sequence > 0) {
        std::vector<Ref> refs;
        for (std::uint32_t k = 0; k < a.sequence; ++k) refs.push_back(loadRef(frame + k));
        for (const EstimatorSpec& spec : specs) {
            // One history per seed; each frame's metrics are means over the seeds, its time their median.
            Settings s = specSettings(a.scene, a.defines, base, spec);
            s.render.frame_start = frame;
            s.render.frames = a.sequence;
            const std::uint64_t seed0 = s.render.seed;
            std::vector<Point> perFrame(a.sequence);
            std::vector<std::vector<double>> frameSeconds(a.sequence);
            for (std::uint32_t seed = 0; seed < a.seeds; ++seed) {
                s.render.seed = seed0 + seed;
                FrameRenderer renderer(s, source, RenderOptions{true});
                for (std::uint32_t k = 0; k < a.sequence; ++k) {
                    FrameStats stats;
                    const FrameImage img = renderer.render(frame + k, stats);
                    const ErrorMetrics e =
                        computeErrors(img.lighting.Lr, refs[k].Lr, refs[k].hasStderr ? &refs[k].stderr : nullptr);
                    Point& p = perFrame[k];
                    p.label = spec.label;
                    p.frame = frame + k;
                    p.totalSeconds += stats.seconds;
                    p.shadowRays += stats.lighting.shadowRays;
                    p.lightTerms += stats.lighting.lightTerms;
                    p.err.relMSE += e.relMSE / a.seeds;
                    p.err.MSE += e.MSE / a.seeds;
                    p.err.MAPE += e.MAPE / a.seeds;
                    p.err.relMSEFloor = e.relMSEFloor;
                    p.err.pixels = e.pixels;
                    frameSeconds[k].push_back(stats.seconds);
                }
            }
            for (std::uint32_t k = 0; k < a.sequence; ++k) {
                Point& p = perFrame[k];
                std::sort(frameSeconds[k].begin(), frameSeconds[k].end());
                p.seconds = frameSeconds[k][frameSeconds[k].size() / 2];
                p.shadowRays /= a.seeds;
                p.lightTerms /= a.seeds;
                if (!a.quiet)
                    fmt::print(stderr, "converge: {} frame {}: {:.3f} s, relMSE {:.4g}, MAPE {:.4g}\n", spec.label, p.frame,
                               p.seconds, p.err.relMSE, p.err.MAPE);
                points.push_back(p);
            }
        }
    } else {
        const Ref ref = loadRef(frame);
        for (const EstimatorSpec& spec : specs) {
            double spent = 0.0, last = 0.0;
            for (std::uint32_t effort = a.minEffort; effort <= a.maxEffort; effort *= 2) {
                if (spent > 0.0 && spent + 2.2 * last > budget) break;  // the next level would overrun the budget
                EstimatorSpec level = spec;
                const std::string flag = fmt::format("--min-effort/--max-effort (level {})", effort);
                if (spec.kind == EstimatorKind::restir)
                    level.settings.push_back({"render.candidates", flag, [effort](Settings& st) { st.render.candidates = effort; }});
                else
                    level.settings.push_back({"render.samples", flag, [effort](Settings& st) { st.render.samples = effort; }});
                Settings s = specSettings(a.scene, a.defines, base, level);
                // Metrics are means over --seeds independent renders; time per frame is their median.
                Point p{spec.label, frame, effort, 0.0, 0.0, 0, 0, {}};
                std::vector<double> frameSeconds;
                const std::uint64_t seed0 = s.render.seed;
                for (std::uint32_t k = 0; k < a.seeds; ++k) {
                    s.render.seed = seed0 + k;
                    const ExperimentRender r = renderForExperiment(s, source, frame, a.history);
                    const ErrorMetrics e = computeErrors(r.image.lighting.Lr, ref.Lr, ref.hasStderr ? &ref.stderr : nullptr);
                    frameSeconds.push_back(r.frameSeconds);
                    p.totalSeconds += r.totalSeconds;
                    p.shadowRays += r.stats.lighting.shadowRays;
                    p.lightTerms += r.stats.lighting.lightTerms;
                    p.err.relMSE += e.relMSE / a.seeds;
                    p.err.MSE += e.MSE / a.seeds;
                    p.err.MAPE += e.MAPE / a.seeds;
                    p.err.relMSEFloor = e.relMSEFloor;
                    p.err.pixels = e.pixels;
                }
                std::sort(frameSeconds.begin(), frameSeconds.end());
                p.seconds = frameSeconds[frameSeconds.size() / 2];
                p.shadowRays /= a.seeds;
                p.lightTerms /= a.seeds;
                if (!a.quiet)
                    fmt::print(stderr, "converge: {} x{}: {:.3f} s, relMSE {:.4g} (reference noise {:.3g})\n", spec.label,
                               effort, p.seconds, p.err.relMSE, p.err.relMSEFloor);
                points.push_back(p);
                spent += p.totalSeconds;
                last = p.totalSeconds;
                if (spec.kind == EstimatorKind::exact) break;
            }
        }
    }

    // CSV, one row per point.
    std::string csv = "estimator,frame,effort,seconds,total_seconds,shadow_rays,light_terms,relMSE,MSE,MAPE,relMSE_reference_noise,relMSE_corrected\n";
    for (const Point& p : points)
        csv += fmt::format("{},{},{},{:.6g},{:.6g},{},{},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g}\n", p.label, p.frame, p.effort,
                           p.seconds, p.totalSeconds, p.shadowRays, p.lightTerms, p.err.relMSE, p.err.MSE, p.err.MAPE,
                           p.err.relMSEFloor, p.err.relMSE - p.err.relMSEFloor);
    writeFileAtomic(prefix + ".csv", csv);

    // Summary: each estimator's last point, and for every other estimator the
    // time the baseline (first Monte Carlo estimator listed) needs for the same error.
    nlohmann::json summary = nlohmann::json::array();
    std::vector<Point> baseline;
    std::string baselineLabel;
    for (const EstimatorSpec& spec : specs)
        if (spec.kind == EstimatorKind::uniform || spec.kind == EstimatorKind::power || spec.kind == EstimatorKind::tree) {
            baselineLabel = spec.label;
            for (const Point& p : points)
                if (p.label == spec.label) baseline.push_back(p);
            break;
        }
    if (a.sequence == 0) {
        fmt::print("{:<28} {:>7} {:>10} {:>12} {:>12} {:>14}\n", "estimator", "effort", "s/frame", "relMSE",
                   "relMSE-noise", baselineLabel.empty() ? "" : "speed-up vs " + baselineLabel);
        for (const EstimatorSpec& spec : specs) {
            for (const Point& p : points) {
                if (p.label != spec.label) continue;
                const double corrected = p.err.relMSE - p.err.relMSEFloor;
                const double tBase = baseline.empty() || corrected <= 0.0 ? NAN : timeAtError(baseline, corrected);
                fmt::print("{:<28} {:>7} {:>10.4f} {:>12.5g} {:>12.5g} {:>14.3g}\n", p.label, p.effort, p.seconds,
                           p.err.relMSE, corrected, tBase / p.seconds);
                summary.push_back({{"estimator", p.label}, {"effort", p.effort}, {"seconds", p.seconds},
                                   {"relMSE", p.err.relMSE}, {"relMSE_corrected", corrected}, {"MSE", p.err.MSE},
                                   {"MAPE", p.err.MAPE}, {"baseline", baselineLabel},
                                   {"baseline_seconds_at_equal_error", std::isfinite(tBase) ? nlohmann::json(tBase) : nlohmann::json()},
                                   {"speedup_at_equal_error", std::isfinite(tBase) ? nlohmann::json(tBase / p.seconds) : nlohmann::json()}});
            }
        }
    }
    writeJson(prefix + ".json", {{"version", std::string(version())},
                                 {"command", "converge"},
                                 {"scene", sceneSettings.scenePath},
                                 {"reference", a.reference},
                                 {"frame", frame},
                                 {"budget_seconds", budget},
                                 {"history_frames", a.history},
                                 {"seeds_per_point", a.seeds},
                                 {"speedup_model", "baseline relMSE = c / seconds, c fitted over its curve"},
                                 {"estimators", a.estimators},
                                 {"settings", settingsToToml(sceneSettings)},
                                 {"points", summary}});

    // Plot: relMSE against time and against shadow rays (or against frame).
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
    if (a.sequence > 0) {
        // Table: relMSE (MAPE) at frames 0, 1, 3, 7, 15, 31, ... of the sequence.
        std::vector<std::uint32_t> shown;
        for (std::uint32_t k = 1; k <= a.sequence; k *= 2) shown.push_back(k - 1);
        if (shown.back() != a.sequence - 1) shown.push_back(a.sequence - 1);
        fmt::print("{:<44}", "relMSE (MAPE) at sequence frame");
        for (std::uint32_t k : shown) fmt::print(" {:>15}", k);
        fmt::print("\n");
        for (const EstimatorSpec& spec : specs) {
            fmt::print("{:<44}", spec.label);
            for (std::uint32_t k : shown)
                for (const Point& p : points)
                    if (p.label == spec.label && p.frame == frame + k)
                        fmt::print(" {:>15}", fmt::format("{:.3g} ({:.3f})", p.err.relMSE, p.err.MAPE));
            fmt::print("\n");
        }
        script += "set xlabel 'frame'\nplot " + withColumn("2") + "\n";
        plotPng(prefix + ".png", script);
    } else {
        script += "set multiplot layout 1,2\nset logscale x\nset xlabel 'seconds per frame'\nplot " + withColumn("4") +
                  "\nset xlabel 'shadow rays'\nplot " + withColumn("6") + "\nunset multiplot\n";
        plotPng(prefix + ".png", script, 1400, 600);
    }
    fmt::print("converge: {}.csv, {}.png, {}.json\n", prefix, prefix, prefix);
}

}  // namespace

void addConvergeCommand(CLI::App& app) {
    auto args = std::make_shared<ConvergeArgs>();
    CLI::App* cmd = app.add_subcommand("converge", "Error against time and rays per estimator, against a reference EXR");
    addSceneOptions(cmd, *args, "Frames A:B (= render.frame_start, render.frames); the first is measured");
    cmd->add_option("--reference", args->reference, "Reference EXR with an Lr layer ({frame} pattern with --sequence)")->required();
    cmd->add_option("--estimators", args->estimators,
                    "Comma-separated specs name[:option...]: uniform, power, tree, ris[:power], restir[:none|basic|basic+vis|pairwise], "
                    "options key=value override settings");
    cmd->add_option("--budget", args->budget, "Time budget per estimator (e.g. 60s, 2m)");
    cmd->add_option("--frame", args->frame, "Frame measured (default render.frame_start)");
    cmd->add_option("--history", args->history, "restir: frames rendered before the measured one");
    cmd->add_option("--sequence", args->sequence, "Error per frame over N frames from --frame (one history per estimator)");
    cmd->add_option("--min-effort", args->minEffort, "First spp (restir: candidates) tried; doubled from there")
        ->check(CLI::Range(1u, 1u << 30));
    cmd->add_option("--max-effort", args->maxEffort, "Largest spp (restir: candidates) tried");
    cmd->add_option("--seeds", args->seeds, "Renders per point: errors are their means, time their median")
        ->check(CLI::Range(1u, 100000u));
    cmd->add_option("-o,--out", args->out, "Output prefix (default out/<scene>.converge): .csv, .png, .json");
    cmd->footer("Effort doubles from --min-effort (spp; ris reservoirs; restir candidates) until the budget is spent.\n"
                "relMSE_corrected subtracts the reference's own noise (its Lr_stderr layer) in expectation.");
    cmd->callback([args] { runConverge(*args); });
}

}  // namespace accretion::cmd
