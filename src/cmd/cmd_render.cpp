// accretion render: frames of a scene to EXR + PNG preview + stats.json.
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include <fmt/core.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/memory.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/version.h"
#include "accretion/gpu/gpu_report.h"
#include "accretion/io/accumulation_file.h"
#include "accretion/io/checkpoint.h"
#include "accretion/io/render_session.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/preview.h"
#include "accretion/io/stats_writer.h"
#include "accretion/particles/particle_source.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"
#include "explain_pixel.h"

namespace accretion::cmd {

namespace {

struct RenderArgs : SceneArgs {
    std::string output, estimator;
    std::optional<std::uint32_t> spp;
    std::optional<std::uint64_t> seed;
    std::string targetStderr;
    std::string shard;               ///< --shard i/n
    bool resume = false;             ///< --resume
    double checkpointEvery = 300.0;  ///< --checkpoint-every seconds (0: only on SIGINT/SIGTERM)
    std::string outputsFile;         ///< --outputs-file: a JSON list of every file written (for batch)
    std::string crop;                ///< --crop x0,x1,y0,y1 (= render.crop)
    std::string pixel;               ///< --pixel x,y: explain one pixel, write nothing
};

/// "a,b,..." as `count` unsigned integers, or an error naming the option.
std::vector<std::uint32_t> parseInts(const std::string& text, std::size_t count, const char* option, const char* form) {
    const std::vector<std::string> parts = splitList(text, ',');
    std::vector<std::uint32_t> v;
    for (const std::string& part : parts)
        if (const std::optional<std::uint64_t> n = parseUnsigned(part, 16384)) v.push_back(std::uint32_t(*n));
    if (parts.size() != count || v.size() != count)
        throw InputError(fmt::format("command line {} {}: expected {} (pixel coordinates, integers >= 0)", option, text, form));
    return v;
}

/// "out/x.0008.exr" -> "out/x.0008.shard1of4.exr" (--shard 1/4).
std::string shardPath(const std::string& path, const Shard& shard) {
    if (shard.whole()) return path;
    std::filesystem::path p(path);
    return (p.parent_path() / (p.stem().string() + "." + shard.name() + p.extension().string())).string();
}

/// "0.5%" -> 0.005, "0.005" -> 0.005.
double parseRelative(const std::string& text, const char* option) {
    std::string t = text;
    double scale = 1.0;
    if (!t.empty() && t.back() == '%') {
        t.pop_back();
        scale = 0.01;
    }
    const std::optional<double> v = parseNumber(t);
    if (!v || !(*v >= 0.0))
        throw InputError(fmt::format("command line {} {}: expected a non-negative number or percentage", option, text));
    return *v * scale;
}

/// "out/{scene}.{frame}.exr" -> "out/<scene>" (the {frame} part and extension dropped).
std::string runStem(const Settings& s) {
    std::string pattern = s.render.output;
    const auto f = pattern.find("{frame}");
    if (f != std::string::npos) {
        std::size_t begin = f;
        if (begin > 0 && (pattern[begin - 1] == '.' || pattern[begin - 1] == '_' || pattern[begin - 1] == '-')) --begin;
        pattern.erase(begin, f + 7 - begin);
    }
    std::filesystem::path p = expandPattern(pattern, s.sceneName, 0);
    return (p.parent_path() / p.stem()).string();
}

/// The render flags as the settings they set (typed, and errors name the flag).
std::vector<FlagSetting> renderFlags(const RenderArgs& args) {
    std::vector<FlagSetting> flags;
    if (!args.output.empty())
        flags.push_back({"render.output", "-o " + args.output, [o = args.output](Settings& s) { s.render.output = o; }});
    if (!args.estimator.empty()) {
        EstimatorKind e;
        if (!parseEnum(args.estimator, e))
            throw InputError(fmt::format("command line --estimator {}: unknown estimator (expected {})", args.estimator,
                                         enumChoices<EstimatorKind>()));
        flags.push_back({"render.estimator", "--estimator " + args.estimator, [e](Settings& s) { s.render.estimator = e; }});
    }
    if (args.spp)
        flags.push_back({"render.samples", fmt::format("--spp {}", *args.spp), [n = *args.spp](Settings& s) { s.render.samples = n; }});
    if (args.seed)
        flags.push_back({"render.seed", fmt::format("--seed {}", *args.seed), [n = *args.seed](Settings& s) { s.render.seed = n; }});
    if (!args.crop.empty() && !args.pixel.empty())
        throw InputError(fmt::format("command line --crop {} --pixel {}: give one (--pixel renders its own window)", args.crop, args.pixel));
    if (!args.crop.empty()) {
        const std::vector<std::uint32_t> c = parseInts(args.crop, 4, "--crop", "x0,x1,y0,y1");
        flags.push_back({"render.crop", "--crop " + args.crop,
                         [c](Settings& s) { s.render.crop = {double(c[0]), double(c[1]), double(c[2]), double(c[3])}; }});
    }
    if (!args.pixel.empty()) {
        const std::vector<std::uint32_t> p = parseInts(args.pixel, 2, "--pixel", "x,y");
        flags.push_back({"render.crop", "--pixel " + args.pixel, [p](Settings& s) {
                             s.render.crop = {double(p[0]), double(p[0]) + 1, double(p[1]), double(p[1]) + 1};
                         }});
    }
    if (!args.targetStderr.empty()) {
        const double t = parseRelative(args.targetStderr, "--target-stderr");
        flags.push_back({"render.target_stderr", "--target-stderr " + args.targetStderr,
                         [t](Settings& s) { s.render.target_stderr = t; }});
    }
    return flags;
}

/// Which frames this process renders and how a shard splits the work:
/// accumulating estimators checkpoint and shard their samples (exact: row
/// bands); adaptive sampling and restir shard whole frames instead.
Sharding planSharding(const Settings& settings, const RenderArgs& args) {
    Sharding s;
    s.shard = args.shard.empty() ? Shard{} : parseShard(args.shard, "--shard");
    if (!s.shard.whole() && !settings.render.crop.empty())
        throw InputError(fmt::format("command line --shard {}: render.crop renders a window; render it whole (shards split whole images)",
                                     args.shard));
    s.accumulating = !estimatorInfo(settings.render.estimator).reuse;
    s.bySamples = !s.shard.whole() && s.accumulating && !(settings.render.target_stderr > 0.0);
    s.first = settings.render.frame_start;
    s.end = s.first + settings.render.frames;
    if (!s.shard.whole() && !s.bySamples) {
        const std::uint32_t F = settings.render.frames;
        if (F < s.shard.count)
            throw InputError(fmt::format("command line --shard {}: {} shards of {} frame(s): {} cannot split samples, so give at "
                                         "least as many frames as shards", args.shard, s.shard.count, F,
                                         s.accumulating ? "adaptive sampling" : "restir"));
        s.first = settings.render.frame_start + std::uint32_t(std::uint64_t(F) * s.shard.index / s.shard.count);
        s.end = settings.render.frame_start + std::uint32_t(std::uint64_t(F) * (s.shard.index + 1) / s.shard.count);
    }
    if (s.bySamples) planLighting(settings.render, settings.camera.height, s.shard);  // can it be cut? (throws)
    if (!(args.checkpointEvery >= 0.0))
        throw InputError(fmt::format("command line --checkpoint-every {}: expected seconds >= 0", args.checkpointEvery));
    return s;
}

/// What the run's outputs record.
struct RenderRun {
    const Settings& settings;
    const Sharding& sharding;
    std::string settingsToml;
    std::string shardLabel;  ///< "i/n"
    OutputGuard guard = {};  ///< the run's inputs, which no output may replace
};

/// A frame's image outputs: the EXR and, beside it, its previews and (shards
/// of samples) the sums a merge needs.
struct FramePaths {
    std::string exr, base;
    std::string png() const { return base + ".png"; }
    std::string lrPng() const { return base + ".Lr.png"; }
    std::string acc() const { return base + ".acc"; }
};

FramePaths framePaths(const RenderRun& run, std::uint32_t frame) {
    const Settings& s = run.settings;
    FramePaths p;
    p.exr = shardPath(expandPattern(s.render.output, s.sceneName, frame), run.sharding.samples());
    p.base = std::filesystem::path(p.exr).replace_extension().string();
    return p;
}

/// Before anything is written: the run reads its scene and particle files
/// (every frame's checked now: exists, header, size, count), and no output of
/// any frame, nor the run's stats, settings, checkpoint or list, may replace
/// one of them or land on a device or a directory.
void guardRun(RenderRun& run, const std::string& stem, const std::string& outputsFile) {
    const Settings& s = run.settings;
    run.guard = sceneInputs(s, run.sharding.first, run.sharding.end);
    for (std::uint32_t frame = run.sharding.first; frame < run.sharding.end; ++frame) {
        const FramePaths p = framePaths(run, frame);
        for (const std::string& out : {p.exr, p.png(), p.lrPng()}) run.guard.check(out, "output");
        if (run.sharding.bySamples) run.guard.check(p.acc(), "output");
    }
    for (const char* suffix : {".settings.toml", ".stats.json", ".checkpoint"}) run.guard.check(stem + suffix, "output");
    if (!outputsFile.empty()) run.guard.check(outputsFile, "--outputs-file");
}

/// The writeOutputs pass of a frame: EXR, previews, a shard's sums and the
/// counter heatmaps; returns the frame's stats with its outputs.
nlohmann::json writeFrameOutputs(const RenderRun& run, std::uint32_t frame, const FrameImage& image, FrameStats& fs,
                                 const Accumulation& sums) {
    const Settings& settings = run.settings;
    const FramePaths paths = framePaths(run, frame);
    const std::string& exr = paths.exr;
    const std::string& base = paths.base;
    for (const Heatmap& h : image.heatmaps) run.guard.check(base + "." + h.name + ".png", "output");
    // The previews show the rendered window; their tone is stated in the EXR.
    const PixelWindow& w = image.window;
    const std::vector<Vec3>& L = image.L;
    const std::vector<Vec3>& Lr = image.lighting.Lr;
    const RenderSettings& rs = settings.render;
    const PreviewTone tone = previewTone(L, rs.tonemap, rs.auto_exposure, rs.exposure);
    const PreviewTone lrTone = previewTone(Lr, rs.tonemap, rs.auto_exposure, rs.exposure);
    OutputMetadata meta = frameMetadata(settings, run.settingsToml, frame, settings.render.seed, run.shardLabel, fs.seconds);
    meta["preview"] = tone.describe();
    nlohmann::json outputs;
    {
        auto t = fs.timer.scope(Pass::writeOutputs);
        writeFrameExr(exr, image, !estimatorInfo(settings.render.estimator).sums, meta);
        writePreviewPng(base + ".png", L, w.width(), w.height(), tone);
        writePreviewPng(base + ".Lr.png", Lr, w.width(), w.height(), lrTone);
        outputs = {{"exr", exr}, {"png", base + ".png"}, {"lr_png", base + ".Lr.png"}, {"preview_tone", tone.describe()}};
        if (run.sharding.bySamples) {  // the sums a merge needs, next to the EXR
            const LightingPlan plan = planLighting(settings.render, image.height, run.sharding.shard);
            AccumulationFile f{accumulationHeader("shard", run.settingsToml, run.shardLabel, frame), sums};
            f.header["chunks"] = {plan.begin, plan.end};
            f.header["exact"] = plan.exact;
            writeAccumulationFile(base + ".acc", f);
            outputs["accumulation"] = base + ".acc";
        }
    }
    nlohmann::json fj = frameStatsJson(fs);
    fj["outputs"] = outputs;
    if (settings.gpu.counters) {
        // The GPU model of the frame, and a PNG of each counter heatmap.
        fj["gpu"] = toJson(makeGpuReport(image.counters, settings, fs.reservoirBytes));
        for (const Heatmap& h : image.heatmaps) {
            const std::string png = base + "." + h.name + ".png";
            writeHeatmapPng(png, h.values, image.window.width(), image.window.height(),
                            h.name + ": " + h.unit);
            fj["outputs"][h.name + "_png"] = png;
        }
    }
    return fj;
}

/// The frame's lines on stdout.
void printFrame(const Settings& settings, std::uint32_t frame, const nlohmann::json& fj, const FrameStats& fs) {
    if (settings.render.target_stderr > 0.0)
        fmt::print("  adaptive: mean {:.1f}, max {:.0f} samples per hit pixel\n", fs.meanSpp, fs.maxSpp);
    for (const auto& [pass, count] : fs.nonFinite)
        fmt::print("  {}: {} non-finite values rejected ({})\n", passName(pass), count, enumName(settings.render.nonfinite));
    const double lighting = fs.timer.seconds(Pass::estimateLighting);
    fmt::print("frame {}: {} ({:.2f} s, {} particles, CPU traces {}, build {:.1f} ms, {:.2f} M shadow rays/s)\n", frame,
               fj["outputs"]["exr"].get<std::string>(), fs.seconds, fs.particles, fs.bvh.layout,
               1e3 * (fs.bvh.clusterSeconds + fs.bvh.blasSeconds + fs.bvh.tlasSeconds),
               lighting > 0 ? 1e-6 * double(fs.lighting.shadowRays) / lighting : 0.0);
    const std::string base = std::filesystem::path(fj["outputs"]["exr"].get<std::string>()).replace_extension().string();
    fmt::print("  preview: {}.png, lighting only: {}.Lr.png\n", base, base);
}

/// Once every frame is out (a run stopped by bad input leaves nothing): the
/// settings, the stats and, when asked, the list of every file written.
void writeRunOutputs(const std::string& stem, const std::string& settingsToml, const nlohmann::json& stats,
                     const std::string& outputsFile) {
    writeFileAtomic(stem + ".settings.toml", settingsToml);
    writeJson(stem + ".stats.json", stats);
    if (outputsFile.empty()) return;
    nlohmann::json manifest = {{"stats", stem + ".stats.json"}, {"settings", stem + ".settings.toml"},
                               {"frames", nlohmann::json::array()}};
    for (const auto& f : stats["frames"]) manifest["frames"].push_back(f["outputs"]);
    writeJson(outputsFile, manifest);
}

/// The run's stats.json before its frames: what made it.
nlohmann::json runStats(const RenderRun& run, int threads) {
    nlohmann::json stats = statsHeader(run.settings, run.settingsToml);
    stats["threads"] = threads;
    stats["shard"] = run.shardLabel;
    stats["shard_by"] = run.sharding.shard.whole() ? "none" : run.sharding.bySamples ? "samples" : "frames";
    return stats;
}

void runRender(const RenderArgs& args) {
    const Settings settings = loadSceneArgs(args, renderFlags(args));
    const auto threads = limitThreads(args.threads);
    const Sharding sharding = planSharding(settings, args);
    if (!args.pixel.empty()) {  // one pixel explained on stdout; nothing written
        if (args.resume || !args.outputsFile.empty())
            throw InputError("command line --pixel: writes no file, so --resume and --outputs-file do not apply");
        sceneInputs(settings, sharding.first, sharding.end);
        explainPixel(settings, std::uint32_t(settings.render.crop[0]), std::uint32_t(settings.render.crop[2]), args.quiet);
        return;
    }
    const Shard& shard = sharding.shard;
    const std::string stem = shardPath(runStem(settings), shard);
    RenderRun run{settings, sharding, settingsToToml(settings), fmt::format("{}/{}", shard.index, shard.count)};
    guardRun(run, stem, args.outputsFile);
    const OutputLock lock(stem + ".lock");  // one run at a time writes these outputs
    removeStaleTemporaries(std::filesystem::path(stem).parent_path());
    nlohmann::json stats = runStats(run, args.threads > 0 ? args.threads : tbb::info::default_concurrency());
    RenderSession session(settings, stem + ".checkpoint", run.settingsToml, sharding,
                          SessionOptions{args.resume, args.checkpointEvery, args.quiet}, stats);
    const RenderSession::Totals t = session.run([&](std::uint32_t frame, const FrameImage& image, FrameStats& fs,
                                                    const Accumulation& sums) {
        nlohmann::json fj = writeFrameOutputs(run, frame, image, fs, sums);
        printFrame(settings, frame, fj, fs);
        return fj;
    });
    stats["total_seconds"] = t.seconds;
    stats["peak_rss_bytes"] = peakResidentBytes();
    stats["shadow_rays_per_second"] = t.lightingSeconds > 0 ? double(t.shadowRays) / t.lightingSeconds : 0.0;
    writeRunOutputs(stem, run.settingsToml, stats, args.outputsFile);
    session.finish();  // done: nothing left to resume
    fmt::print("stats: {}.stats.json\nsettings: {}.settings.toml\ntotal: {:.2f} s\n", stem, stem, t.seconds);
}

}  // namespace

void addRenderCommand(CLI::App& app) {
    auto args = std::make_shared<RenderArgs>();
    CLI::App* cmd = app.add_subcommand("render", "Render frames of a scene to EXR (+ PNG preview, stats.json)");
    addSceneOptions(cmd, *args, "Frames A:B, half-open (= render.frame_start, render.frames)");
    cmd->add_option("-o,--output", args->output, "EXR output path ({scene}, {frame} patterns) = render.output");
    cmd->add_option("--estimator", args->estimator,
                    fmt::format("{}  (= render.estimator; `accretion estimators` says what each needs)", enumChoices<EstimatorKind>()));
    cmd->add_option("--target-stderr", args->targetStderr,
                    "Sample each pixel until its relative standard error is below this (e.g. 0.5%; = render.target_stderr)");
    cmd->add_option("--spp", args->spp, "Light samples per pixel (= render.samples)");
    cmd->add_option("--seed", args->seed, "Render seed (= render.seed)")->check(unsignedNumber());
    cmd->add_option("--shard", args->shard,
                    "Render part i/n (0 <= i < n) of the work: a sample range (exact: rows) with its own streams, "
                    "to combine with `accretion merge`; adaptive sampling and restir split frames");
    cmd->add_option("--crop", args->crop,
                    "Render only the pixels x0 <= x < x1, y0 <= y < y1 (the EXR's data window; each pixel equals the whole "
                    "image's) = render.crop");
    cmd->add_option("--pixel", args->pixel,
                    "Explain pixel x,y of the last frame on stdout: its hit, the estimator's terms, samples or reservoirs, "
                    "and its value (bit for bit the full render's); writes no file");
    cmd->add_flag("--resume", args->resume, "Continue from the checkpoint of an interrupted run (same command line)");
    cmd->add_option("--outputs-file", args->outputsFile,
                    "Write a JSON list of the files this run wrote (stats, settings, each frame's outputs) here at the end");
    cmd->add_option("--checkpoint-every", args->checkpointEvery,
                    "Seconds between checkpoints of the lighting sums (default 300; 0: only on SIGINT/SIGTERM)");
    cmd->add_flag_callback("--help-settings", [] {
        fmt::print("Scene settings (section.key = default  # meaning):\n{}", settingsReference());
        throw CLI::Success();
    }, "List every scene setting with its default and meaning");
    cmd->footer("Every -D key is a scene setting; see --help-settings. Exit codes: 0 ok, 1 bad input, 3 internal error.");
    cmd->callback([args] { runRender(*args); });
}

}  // namespace accretion::cmd
