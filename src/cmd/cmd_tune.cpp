// accretion tune: the GPU frame's configuration for a time budget. It
// searches the configuration space with the calibrated cost model for the
// GPU time (`accretion cost` of each configuration at the scene's
// resolution) and the CPU for the error (`accretion bias` of each lighting
// configuration over seeds at a small resolution, against a reference),
// prints the Pareto front of predicted GPU ms against relMSE, marks biased
// configurations and recommends the best one under the budget.
//
// The search is separable: the acceleration structure's layout, build
// policy and alpha path change no image (docs/MODEL.md section 2), so they
// are chosen by predicted time alone, at the scene's lighting; the lighting
// configurations are then measured for error and priced on that geometry.
// Every measurement is a child process whose result is cached by a hash of
// everything it depends on (the accretion version included), so a second
// run reads them back. The GPU time is priced here from the cached
// counters, with gpu.coefficients' calibration (the committed one by
// default), so that a new calibration re-prices without measuring again.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/core/version.h"
#include "accretion/gpu/cost_model.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "accretion/io/stats_writer.h"
#include "accretion/particles/particle_source.h"
#include "child_process.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct TuneArgs : SceneArgs {
    double budgetMs = 0.0;
    std::optional<double> maxError;
    std::uint32_t seeds = 16;
    std::uint32_t frame = 1;
    std::string errorSize = "320x180";
    std::string space = "quick";
    std::string reference;
    std::uint32_t referenceSpp = 1024;
    std::string out, cache;
    bool allowBiased = false;
};

/// One point of the space: its label and the settings it overrides.
struct Option {
    std::string label;
    std::vector<std::string> defines;  ///< section.key=value
};

/// The geometry choices (none changes the image): layout and cluster size,
/// build policy, and for disc alpha the any-hit or a 4-state micromap.
std::vector<Option> geometryOptions(const Settings& s) {
    struct Layout {
        std::string label;
        std::vector<std::string> defines;
    };
    const std::string all = "geometry.cluster_size=10000000";
    std::vector<Layout> layouts = {{"clusters of 100", {"geometry.layout=clusters", "geometry.cluster_size=100"}},
                                   {"clusters of 1000", {"geometry.layout=clusters", "geometry.cluster_size=1000"}},
                                   {"clusters of 10000", {"geometry.layout=clusters", "geometry.cluster_size=10000"}},
                                   {"one BLAS", {"geometry.layout=clusters", all}},
                                   {"instance per particle", {"geometry.layout=instances"}}};
    if (s.geometry.primitive == Primitive::billboard) layouts.push_back({"one BLAS of boxes", {"geometry.layout=aabbs", all}});
    std::vector<Option> out;
    for (const Layout& l : layouts)
        for (const char* build : {"rebuild", "refit"}) {  // every layout's refit is timed (bench/gpu/layouts_refit.txt)
            std::vector<std::string> alphas = {""};
            if (s.geometry.alpha == AlphaMode::disc && l.defines[0] != "geometry.layout=aabbs") alphas.push_back("omm");
            for (const std::string& alpha : alphas) {
                Option o{fmt::format("{}, {}{}", l.label, build, alpha.empty() ? "" : ", 4-state micromap L4"), l.defines};
                o.defines.push_back(fmt::format("geometry.build={}", build));
                if (!alpha.empty()) o.defines.insert(o.defines.end(), {"gpu.omm=4state", "gpu.omm_level=4"});
                else o.defines.push_back("gpu.omm=off");
                out.push_back(std::move(o));
            }
        }
    return out;
}

/// The lighting choices of `space`: candidate source and count, spatial
/// neighbours and iterations, bias correction, visibility reuse and the
/// lighting resolution. quick: 34 points around the GPU team's settings;
/// full: the whole grid (1080 points: hours).
std::vector<Option> lightingOptions(const std::string& space) {
    struct Axes {
        std::vector<std::string> sources;
        std::vector<std::uint32_t> candidates;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> spatial;  // neighbours, iterations
        std::vector<std::string> corrections;
        std::vector<bool> visibility;
        std::vector<double> scales;
    };
    Axes x;
    if (space == "full") {
        x = {{"uniform", "power", "tree"}, {4, 8, 16, 32}, {{0, 1}, {3, 1}, {5, 1}, {5, 2}, {10, 1}},
             {"none", "basic", "pairwise"}, {false, true}, {1.0, 0.75, 0.5}};
    } else if (space == "quick") {
        x = {{"power", "tree"}, {8, 32}, {{0, 1}, {5, 1}}, {"basic", "pairwise"}, {false}, {1.0, 0.5}};
    } else {
        throw InputError(fmt::format("command line --space {}: expected quick or full", space));
    }
    auto option = [](const std::string& src, std::uint32_t m, std::pair<std::uint32_t, std::uint32_t> sp, const std::string& bc,
                     bool vis, double scale) {
        Option o;
        o.label = fmt::format("{} M={} nb={}x{} {}{} {:g}x", src, m, sp.first, sp.second, bc, vis ? "+vis" : "", scale);
        o.defines = {"render.estimator=restir", fmt::format("render.source={}", src), fmt::format("render.candidates={}", m),
                     fmt::format("restir.spatial_neighbours={}", sp.first), fmt::format("restir.spatial_iterations={}", sp.second),
                     fmt::format("restir.bias_correction={}", bc), fmt::format("restir.visibility_reuse={}", vis),
                     // basic with visibility reuse tests V at the neighbours (unbiased); pairwise cannot.
                     fmt::format("restir.basic_visibility={}", vis && bc == "basic"),
                     fmt::format("restir.resolution_scale={:g}", scale)};
        return o;
    };
    std::vector<Option> out;
    for (const auto& src : x.sources)
        for (std::uint32_t m : x.candidates)
            for (const auto& sp : x.spatial)
                for (const auto& bc : x.corrections)
                    for (bool vis : x.visibility)
                        for (double scale : x.scales) out.push_back(option(src, m, sp, bc, vis, scale));
    if (space == "quick") {  // a biased correction and visibility reuse, beside the grid
        out.push_back(option("tree", 16, {5, 1}, "none", false, 1.0));
        out.push_back(option("tree", 16, {5, 1}, "pairwise", true, 1.0));
    }
    return out;
}

/// FNV-1a over the text: the cache key of a measurement.
std::string cacheKey(const std::string& text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    return fmt::format("{:016x}", h);
}

/// The search's fixed inputs: this build, the scene file and its overrides.
struct TuneContext {
    const TuneArgs& args;
    std::filesystem::path cache;
    std::string sceneText;  ///< version + scene file + overrides: every cache key starts with it
    std::uint32_t errorWidth = 0, errorHeight = 0;
    std::string reference;
    CostCoefficients coefficients;  ///< what prices the counters
    std::size_t step = 0, steps = 0;
};

/// Runs `argv` (this executable) unless `result` exists; its log beside it.
void measure(TuneContext& t, const std::vector<std::string>& argv, const std::filesystem::path& result, const std::string& what) {
    ++t.step;
    if (std::filesystem::exists(result)) {
        if (!t.args.quiet) fmt::print(stderr, "tune: [{}/{}] {} (cached)\n", t.step, t.steps, what);
        return;
    }
    if (!t.args.quiet) fmt::print(stderr, "tune: [{}/{}] {}\n", t.step, t.steps, what);
    const std::filesystem::path log = result.string() + ".log";
    const int rc = runSelf(argv, log);
    if (rc != 0 || !std::filesystem::exists(result))
        throw InternalError(fmt::format("tune: {} failed (exit {}): {} (log {})", what, rc, lastLine(log), log.string()));
}

std::vector<std::string> sceneArgv(const TuneContext& t, const std::string& command, const std::vector<std::string>& defines) {
    std::vector<std::string> a = {"/proc/self/exe", command, t.args.scene};
    for (const std::string& d : t.args.defines) a.insert(a.end(), {"-D", d});
    a.insert(a.end(), {"-D", "render.estimator=restir"});
    for (const std::string& d : defines) a.insert(a.end(), {"-D", d});
    if (t.args.threads > 0) a.insert(a.end(), {"--threads", std::to_string(t.args.threads)});
    return a;
}

/// Predicted GPU ms per pass of one configuration at the scene's
/// resolution: its counters (`accretion cost`, cached) priced with the calibration.
std::map<Pass, double> predictMs(TuneContext& t, const std::vector<std::string>& defines, const std::string& what) {
    std::string key = t.sceneText + "\ncost frame " + std::to_string(t.args.frame);
    for (const std::string& d : defines) key += "\n" + d;
    const std::filesystem::path prefix = t.cache / (cacheKey(key) + ".cost");
    std::vector<std::string> argv = sceneArgv(t, "cost", defines);
    argv.insert(argv.end(), {"--frames", fmt::format("{}:{}", t.args.frame, t.args.frame + 1), "--history", "1", "--overhead", "0",
                             "--cluster-sizes", "", "--omm-levels", "", "--ser-keys", "hit", "-q", "-o", prefix.string() + ".json"});
    measure(t, argv, prefix.string() + ".csv", "GPU time of " + what);
    std::map<Pass, double> ms;  // a pass's runs summed
    for (CostRow& r : readCounterCsv(prefix.string() + ".csv")) {
        r.features[CostFeature::cold_work] =
            coldWork(r.features[CostFeature::rays], r.features[CostFeature::bytes], r.workingSetBytes, t.coefficients.cacheBytes);
        ms[r.pass.pass] += t.coefficients.predictMs(r.pass.pass, r.features);
    }
    return ms;
}

double total(const std::map<Pass, double>& ms) {
    double s = 0.0;
    for (const auto& [pass, v] : ms) s += v;
    return s;
}

/// One lighting configuration's error: bias's row (relMSE of one frame less
/// the reference's noise, the mean signed error's z, the energy loss).
struct ErrorRow {
    double relMse = 0.0, z = 0.0, energyLossPct = 0.0, cpuSecondsPerFrame = 0.0;
    bool biased = false;
};

ErrorRow measureError(TuneContext& t, const Option& o) {
    std::string spec = "restir";
    for (const std::string& d : o.defines)
        if (d != "render.estimator=restir") spec += ":" + d;
    std::string key = t.sceneText + fmt::format("\nbias {} seeds {} frame {} {}x{} reference {}", spec, t.args.seeds, t.args.frame,
                                                t.errorWidth, t.errorHeight, cacheKey(readWholeFile(t.reference, "tune")));
    const std::filesystem::path prefix = t.cache / (cacheKey(key) + ".bias");
    std::vector<std::string> argv = sceneArgv(t, "bias", {fmt::format("camera.width={}", t.errorWidth),
                                                          fmt::format("camera.height={}", t.errorHeight)});
    argv.insert(argv.end(), {"--reference", t.reference, "--estimators", spec, "--seeds", std::to_string(t.args.seeds), "--frame",
                             std::to_string(t.args.frame), "--history", "1", "-q", "-o", prefix.string()});
    measure(t, argv, prefix.string() + ".json", "error of " + o.label);
    const nlohmann::json j = nlohmann::json::parse(readWholeFile(prefix.string() + ".json", "tune"));
    const nlohmann::json& r = j.at("rows").at(0);
    return {r.at("rel_mse").get<double>(), r.at("z").get<double>(), r.at("energy_loss_pct").get<double>(),
            r.at("seconds_per_frame").get<double>(), r.at("biased").get<bool>()};
}

/// The reference of the error measurements: given, or rendered once (exact
/// up to 20K particles, else split at --reference-spp) and cached.
std::string ensureReference(TuneContext& t, std::size_t particles) {
    if (!t.args.reference.empty()) return t.args.reference;
    const bool exact = particles <= 20000;
    const std::string how = exact ? "exact" : fmt::format("split {} spp", t.args.referenceSpp);
    const std::filesystem::path file = t.cache / (cacheKey(t.sceneText + fmt::format("\nreference {} frame {} {}x{}", how, t.args.frame,
                                                                                      t.errorWidth, t.errorHeight)) + ".ref.exr");
    std::vector<std::string> argv = sceneArgv(t, "render", {fmt::format("camera.width={}", t.errorWidth),
                                                            fmt::format("camera.height={}", t.errorHeight)});
    argv.insert(argv.end(), {"--estimator", exact ? "exact" : "split", "--frames", fmt::format("{}:{}", t.args.frame, t.args.frame + 1),
                             "-o", file.string(), "--quiet"});
    if (!exact) argv.insert(argv.end(), {"--spp", std::to_string(t.args.referenceSpp)});
    ++t.steps;
    measure(t, argv, file, fmt::format("reference ({}, {}x{})", how, t.errorWidth, t.errorHeight));
    return file.string();
}

/// A measured configuration of the front's search.
struct ParetoPoint {
    Option lighting;
    double ms = 0.0;
    ErrorRow error;
    bool front = false;
};

/// Marks the Pareto front: no other point is both faster and better.
void markFront(std::vector<ParetoPoint>& points) {
    std::vector<std::size_t> order(points.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return points[a].ms != points[b].ms ? points[a].ms < points[b].ms : points[a].error.relMse < points[b].error.relMse;
    });
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i : order)
        if (points[i].error.relMse < best) {
            points[i].front = true;
            best = points[i].error.relMse;
        }
}

void runTune(const TuneArgs& a) {
    const Settings scene = loadSceneArgs(a, {{"render.estimator", "tune (restir)", [](Settings& s) { s.render.estimator = EstimatorKind::restir; }}});
    requireWholeImage(scene, "tune");
    if (!(a.budgetMs > 0.0) || !std::isfinite(a.budgetMs)) throw InputError("command line --budget-ms: expected a positive number of ms");
    if (a.maxError && (!(*a.maxError > 0.0) || !std::isfinite(*a.maxError)))
        throw InputError("command line --max-error: expected a positive relMSE");
    TuneContext t{a};
    const auto x = a.errorSize.find('x');
    try {
        if (x == std::string::npos) throw std::invalid_argument("no x");
        t.errorWidth = static_cast<std::uint32_t>(std::stoul(a.errorSize.substr(0, x)));
        t.errorHeight = static_cast<std::uint32_t>(std::stoul(a.errorSize.substr(x + 1)));
    } catch (const std::exception&) {
        throw InputError(fmt::format("command line --error-size {}: expected WIDTHxHEIGHT, e.g. 320x180", a.errorSize));
    }
    if (t.errorWidth < 8 || t.errorHeight < 8 || t.errorWidth > 8192 || t.errorHeight > 8192)
        throw InputError(fmt::format("command line --error-size {}: each side 8 to 8192 pixels", a.errorSize));
    const std::vector<Option> geometry = geometryOptions(scene);
    const std::vector<Option> lighting = lightingOptions(a.space);
    const std::string prefix = a.out.empty() ? "out/" + scene.sceneName + ".tune" : a.out;
    t.cache = a.cache.empty() ? std::filesystem::path("out") / "tune_cache" / scene.sceneName : std::filesystem::path(a.cache);
    OutputGuard guard = sceneInputs(scene);
    if (!a.reference.empty()) guard.addInput(a.reference);
    checkOutputs(guard, prefix, {".csv", ".json", ".png"}, "-o");
    std::filesystem::create_directories(t.cache);
    if (auto dir = std::filesystem::path(prefix).parent_path(); !dir.empty()) std::filesystem::create_directories(dir);
    t.coefficients = CostCoefficients::forSetting(scene.gpu.coefficients);
    if (!t.coefficients.calibrated)
        throw InputError("tune: gpu.coefficients = \"uncalibrated\": tune prices with a calibration (the committed one by default)");
    // The cache key: this build, the scene and its overrides (but the
    // calibration, which prices the cached counters here, not in them).
    t.sceneText = std::string(version()) + "\n" + readWholeFile(a.scene, "tune");
    for (const std::string& d : a.defines)
        if (d.rfind("gpu.coefficients", 0) != 0) t.sceneText += "\n-D " + d;
    t.sceneText += "\n-D render.estimator=restir";  // sceneArgv's

    t.steps = geometry.size() + 2 * lighting.size();
    const std::size_t particles = ParticleSource(scene).frame(a.frame).size();
    t.reference = ensureReference(t, particles);

    // Geometry: the same image whatever it is; the fastest predicted frame.
    Option base{"the scene's lighting", {}};
    std::vector<std::pair<Option, std::map<Pass, double>>> geometryMs;
    for (const Option& g : geometry) geometryMs.emplace_back(g, predictMs(t, g.defines, g.label));
    const auto fastest = std::min_element(geometryMs.begin(), geometryMs.end(),
                                          [](const auto& p, const auto& q) { return total(p.second) < total(q.second); });
    const Option& chosen = fastest->first;
    Table gt({{"geometry", "geometry (the image does not depend on it)", -44}, {"build_ms", "build ms", 9, "{:.3f}", "{:.6g}"},
              {"gbuffer_ms", "G-buffer", 9, "{:.3f}", "{:.6g}"}, {"shadow_ms", "shadow", 9, "{:.3f}", "{:.6g}"},
              {"frame_ms", "frame ms", 9, "{:.3f}", "{:.6g}"}});
    const auto of = [](const std::map<Pass, double>& ms, Pass p) { return ms.count(p) ? ms.at(p) : 0.0; };
    for (const auto& [g, ms] : geometryMs)
        gt.add({g.label, of(ms, Pass::buildClusters), of(ms, Pass::traceGBuffer), of(ms, Pass::traceShadowRays), total(ms)});

    // Lighting: error on the CPU, GPU time on the chosen geometry.
    std::vector<ParetoPoint> points;
    for (const Option& l : lighting) {
        ParetoPoint p{l};
        std::vector<std::string> defines = chosen.defines;
        defines.insert(defines.end(), l.defines.begin(), l.defines.end());
        p.ms = total(predictMs(t, defines, l.label));
        p.error = measureError(t, l);
        points.push_back(std::move(p));
    }
    markFront(points);
    std::sort(points.begin(), points.end(), [](const ParetoPoint& p, const ParetoPoint& q) { return p.ms < q.ms; });
    // The recommendation: under the budget (and --max-error), unbiased unless
    // allowed; the lowest error, or with --max-error the fastest that meets it.
    const ParetoPoint* best = nullptr;
    for (const ParetoPoint& p : points) {
        if (p.ms > a.budgetMs || (p.error.biased && !a.allowBiased)) continue;
        if (a.maxError && p.error.relMse > *a.maxError) continue;
        if (!best || (a.maxError ? p.ms < best->ms : p.error.relMse < best->error.relMse)) best = &p;
    }

    Table lt({{"lighting", "lighting (on the chosen geometry)", -36}, {"gpu_ms", "GPU ms", 9, "{:.3f}", "{:.6g}"},
              {"rel_mse", fmt::format("relMSE@{}", a.errorSize), 14, "{:.4g}", "{:.6g}"}, {"z", "bias z", 7, "{:.1f}", "{:.5g}"},
              {"energy_loss_pct", "loss %", 7, "{:.1f}", "{:.5g}"}, {"cpu_s", "CPU s", 7, "{:.2f}", "{:.5g}"},
              {"biased", "", 0, "{}", "{}", false}, {"front", "", 0, "{}", "{}", false},
              {"", "", 0, "{}", "{}", true, "  "}});
    for (const ParetoPoint& p : points)
        lt.add({p.lighting.label, p.ms, p.error.relMse, p.error.z, p.error.energyLossPct, p.error.cpuSecondsPerFrame, p.error.biased,
                p.front,
                std::string(p.front ? "front" : "") + (p.error.biased ? " BIASED" : "") + (&p == best ? " <- recommended" : "")});
    fmt::print("{}\n{}", gt.console(), lt.console());
    fmt::print("geometry: {} ({:.3f} ms predicted at {}x{}, the scene's lighting)\nGPU time: {}\n", chosen.label,
               total(fastest->second), scene.camera.width, scene.camera.height, t.coefficients.source);
    // Procedural boxes beat triangles only where traversal is software: on
    // RT cores every box entered calls the intersection program on the SM
    // (docs/layouts.md). Name the fastest triangle layout beside them.
    const auto triangles = std::min_element(geometryMs.begin(), geometryMs.end(), [](const auto& p, const auto& q) {
        const bool pb = p.first.defines[0] == "geometry.layout=aabbs", qb = q.first.defines[0] == "geometry.layout=aabbs";
        return pb != qb ? qb : total(p.second) < total(q.second);
    });
    if (chosen.defines[0] == "geometry.layout=aabbs" && triangles->first.defines[0] != "geometry.layout=aabbs")
        fmt::print("on a GPU with RT cores prefer {} ({:+.3f} ms here): boxes win only where traversal runs in software\n",
                   triangles->first.label, total(triangles->second) - total(fastest->second));
    if (best)
        fmt::print("recommended under {:g} ms{}: {} + {}: {:.3f} GPU ms predicted, relMSE {:.4g} at {} ({} seeds){}\n", a.budgetMs,
                   a.maxError ? fmt::format(" and relMSE {:g}", *a.maxError) : "", chosen.label, best->lighting.label, best->ms,
                   best->error.relMse, a.errorSize, a.seeds, best->error.biased ? " BIASED" : "");
    else
        fmt::print("no {}configuration is under {:g} ms{}\n", a.allowBiased ? "" : "unbiased ", a.budgetMs,
                   a.maxError ? fmt::format(" with relMSE <= {:g}", *a.maxError) : "");

    std::fflush(stdout);
    writeFileAtomic(prefix + ".csv", lt.csv());
    nlohmann::json recommended = nullptr;
    if (best) {
        std::vector<std::string> defines = chosen.defines;
        defines.insert(defines.end(), best->lighting.defines.begin(), best->lighting.defines.end());
        recommended = {{"geometry", chosen.label}, {"lighting", best->lighting.label}, {"defines", defines}, {"gpu_ms", best->ms},
                       {"rel_mse", best->error.relMse}, {"biased", best->error.biased}};
    }
    writeJson(prefix + ".json", {{"version", std::string(version())}, {"command", "tune"}, {"scene", scene.scenePath},
                                 {"defines", a.defines}, {"settings", settingsToToml(scene)}, {"seed", scene.render.seed},
                                 {"budget_ms", a.budgetMs}, {"max_error", a.maxError ? nlohmann::json(*a.maxError) : nlohmann::json()},
                                 {"seeds", a.seeds}, {"frame", a.frame}, {"error_size", a.errorSize}, {"reference", t.reference},
                                 {"space", a.space}, {"coefficients", t.coefficients.source}, {"geometry", gt.json()},
                                 {"fastest_triangle_geometry", triangles->first.label}, {"chosen_geometry", chosen.label},
                                 {"lighting", lt.json()}, {"recommended", recommended}});
    const std::string csv = gnuplotQuote(prefix + ".csv");
    const std::string script = fmt::format(
        "set datafile separator ','\nset logscale y\nset grid\nset key top right\n"
        "set title {0}\nset xlabel 'predicted GPU ms per frame ({1}; calibrated cost model)'\nset ylabel 'relMSE at {2} ({3} seeds)'\n"
        "set arrow from {4},graph 0 to {4},graph 1 nohead dt 2 lc rgb 'gray40'\n"
        "set label 'budget' at {4},graph 0.95 right offset -0.5,0 tc rgb 'gray40'\n{6}"
        "plot {5} skip 1 using 2:($7 == 0 ? $3 : NaN) with points pt 7 lc rgb 'gray60' title 'configurations', "
        "{5} skip 1 using 2:($7 != 0 ? $3 : NaN) with points pt 2 ps 1.5 lc rgb 'red' title 'biased (|z| > 3.29)', "
        "{5} skip 1 using 2:($8 != 0 ? $3 : NaN) with points pt 6 ps 2 lc rgb 'blue' title 'Pareto front'\n",
        gnuplotQuote(fmt::format("{} ({} particles) at {}x{}: budget {:g} ms", scene.sceneName, particles,
                                 scene.camera.width, scene.camera.height, a.budgetMs)),
        chosen.label, a.errorSize, a.seeds, a.budgetMs, csv,
        best ? fmt::format("set label 'recommended' at {},{} point pt 3 ps 3 lc rgb 'dark-green' offset 1,1 tc rgb 'dark-green'\n", best->ms,
                           best->error.relMse)
             : std::string());
    plotPng(prefix + ".png", script);
    fmt::print("tune: {}.csv, {}.json, {}.png (cache {})\n", prefix, prefix, prefix, t.cache.string());
}

}  // namespace

void addTuneCommand(CLI::App& app) {
    auto args = std::make_shared<TuneArgs>();
    CLI::App* cmd = app.add_subcommand(
        "tune", "Search the GPU frame's configurations: predicted GPU ms (calibrated cost model) against error (CPU), Pareto front, "
                "the best under a budget");
    addSceneOptions(cmd, *args, "");
    cmd->remove_option(cmd->get_option("--frames"));  // tune measures one frame: --frame
    cmd->add_option("--budget-ms", args->budgetMs, "GPU time budget of a frame, ms (the cost model's prediction)")->required();
    cmd->add_option("--max-error", args->maxError, "Recommend the fastest configuration with relMSE at most this (at --error-size)");
    cmd->add_option("--seeds", args->seeds, "Seeds per lighting configuration for its error and bias")->check(CLI::Range(2u, 100000u));
    cmd->add_option("--frame", args->frame, "The measured frame (restir: after one history frame)");
    cmd->add_option("--error-size", args->errorSize, "Resolution of the error measurements, WIDTHxHEIGHT");
    cmd->add_option("--space", args->space, "quick (34 lighting configurations) or full (1080: hours)");
    cmd->add_option("--reference", args->reference,
                    "Reference EXR at --error-size and --frame (default: rendered once, exact up to 20K particles, else split)");
    cmd->add_option("--reference-spp", args->referenceSpp, "split's samples per pixel for the rendered reference")
        ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--cache", args->cache, "Folder of cached measurements (default out/tune_cache/<scene>)");
    cmd->add_flag("--allow-biased", args->allowBiased, "Biased configurations may be recommended");
    cmd->add_option("-o,--output", args->out, "Output prefix (default out/<scene>.tune): .csv, .json, .png");
    cmd->callback([args] { runTune(*args); });
}

}  // namespace accretion::cmd
