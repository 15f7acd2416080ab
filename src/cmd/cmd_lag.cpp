// accretion lag: the lag of a per-particle history, measured on exact frames
// (analysis/history_lag.h): how much of a history's bias the light's own
// change from frame to frame makes, with no noise to average.
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "accretion/analysis/history_lag.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/io/exr_file.h"
#include "accretion/io/report_table.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct LagArgs {
    std::string frames;             ///< {frame} pattern of the exact frames
    std::string range;              ///< --frames A:B
    std::vector<double> history = {0.95};
    std::string start = "mean";     ///< --start first | mean
    std::string layer = "Lr";
    std::string subtract;           ///< --subtract: a {frame} pattern whose light is taken out of each frame's
    std::vector<std::string> windowsOf;  ///< --windows-of: measure the pixels of these EXRs' data windows (crops)
    std::string csv;                ///< --csv FILE: the last frame's particles' light in every frame
    bool json = false;
    bool quiet = false;
};

void runLag(const LagArgs& a) {
    const auto [first, end] = parseHalfOpen(a.range, "--frames");
    for (const std::string* pattern : {&a.frames, &a.subtract})
        if (!pattern->empty() && pattern->find("{frame}") == std::string::npos)
            throw InputError(fmt::format("command line: {} has no {{frame}} pattern (e.g. 'ref.{{frame}}.exr')", *pattern));
    HistoryStart start{};
    if (!parseEnum(a.start, start))
        throw InputError(fmt::format("command line --start {}: must be one of {}", a.start, enumChoices<HistoryStart>()));
    std::vector<LagRule> rules;
    for (const double h : a.history) rules.push_back({h, start});
    OutputGuard guard;
    std::vector<std::string> files, subtracted;
    for (std::uint64_t f = first; f < end; ++f)
        for (auto [pattern, list] : {std::pair{&a.frames, &files}, std::pair{&a.subtract, &subtracted}}) {
            if (pattern->empty()) continue;
            list->push_back(expandPattern(*pattern, "", std::uint32_t(f)));
            if (!std::filesystem::is_regular_file(list->back()))
                throw InputError(fmt::format("{}: not found (frame {} of --frames {})", list->back(), f, a.range));
            guard.addInput(list->back());
        }
    if (!a.csv.empty()) {
        if (std::filesystem::path(a.csv).extension() != ".csv")
            throw InputError(fmt::format("command line --csv {}: must end in .csv", a.csv));
        guard.check(a.csv, "--csv");
    }
    // The frames' size, and --windows-of's crops in it, before any pixel is read.
    const ExrHeader head = readExrHeader(files.front());
    const std::uint32_t width = head.fullWidth, height = head.fullHeight;
    std::vector<bool> measured;  // --windows-of: the crops' pixels alone (a crop's EXR holds its data window in the whole frame)
    if (!a.windowsOf.empty()) {
        measured.assign(std::size_t(width) * height, false);
        for (const std::string& file : a.windowsOf) {
            const ExrHeader crop = readExrHeader(file);
            if (crop.fullWidth != width || crop.fullHeight != height || crop.x0 < 0 || crop.y0 < 0 ||
                crop.x0 + int(crop.width) > int(width) || crop.y0 + int(crop.height) > int(height))
                throw InputError(fmt::format("{}: its window ({}x{} at ({}, {}) of {}x{}) is not one of the {}x{} frames' ({})", file,
                                             crop.width, crop.height, crop.x0, crop.y0, crop.fullWidth, crop.fullHeight, width,
                                             height, files.front()));
            for (std::uint32_t y = 0; y < crop.height; ++y)
                for (std::uint32_t x = 0; x < crop.width; ++x)
                    measured[std::size_t(crop.y0 + int(y)) * width + std::size_t(crop.x0 + int(x))] = true;
        }
    }
    HistoryLag lag(rules);
    for (std::size_t k = 0; k < files.size(); ++k) {
        const RgbLayer light = readExrLayer(files[k], a.layer);
        if (!light.whole())
            throw InputError(fmt::format("{}: a window of {}x{} pixels at ({}, {}); lag reads whole frames", files[k], light.dataWidth,
                                         light.dataHeight, light.x0, light.y0));
        if (light.width != width || light.height != height)
            throw InputError(fmt::format("{}: {}x{} pixels, but {} is {}x{}", files[k], light.width, light.height, files[0], width,
                                         height));
        const std::vector<std::uint32_t> particle = readExrUintChannel(files[k], "particle.id");
        if (particle.size() != light.rgb.size())
            throw InputError(fmt::format("{}: no particle.id channel (a frame of `accretion render` has one)", files[k]));
        if (!subtracted.empty()) {  // e.g. the far light alone: the whole light less a render of the near lights'
            const RgbLayer less = readExrLayer(subtracted[k], a.layer);
            if (!less.whole() || less.width != width || less.height != height)
                throw InputError(fmt::format("{}: {}x{} pixels{}, but {} is {}x{}", subtracted[k], less.width, less.height,
                                             less.whole() ? "" : " (a window)", files[k], width, height));
            if (readExrUintChannel(subtracted[k], "particle.id") != particle)
                throw InputError(fmt::format("{}: its pixels see other particles than {}'s (another frame or view?)", subtracted[k],
                                             files[k]));
            std::vector<Vec3> part = light.rgb;
            for (std::size_t p = 0; p < part.size(); ++p) part[p] -= less.rgb[p];
            lag.addFrame(std::uint32_t(first + k), part, particle, light.rgb);
        } else {
            lag.addFrame(std::uint32_t(first + k), light.rgb, particle);
        }
        if (!a.quiet) fmt::print(stderr, "\raccretion: lag: frame {} ({} of {})", first + k, k + 1, files.size());
    }
    if (!a.quiet) fmt::print(stderr, "\n");
    Table t({{"history", "h", 6, "{:.3f}", "{:.9g}"}, {"start", "start", -6}, {"frames", "frames", 7},
             {"particles", "particles", 10}, {"fresh", "fresh", 8}, {"energy_pct", "energy %", 10, "{:+.3f}", "{:.9g}"},
             {"rel_mse", "relMSE", 12, "{:.4g}", "{:.9g}"}});
    for (const LagOutcome& o : lag.outcomes(measured))
        t.add({o.rule.history, std::string(enumName(o.rule.start)), std::uint64_t(files.size()), std::uint64_t(o.particles),
               std::uint64_t(o.fresh), o.energyPct(), o.relMSE});
    if (!a.csv.empty()) {
        Table trend({{"frame", "frame", 6}, {"ratio", "ratio", 10, "{:.5f}", "{:.9g}"}, {"tracked", "tracked", 8, "{:.3f}", "{:.6f}"}});
        for (const LagTrendPoint& p : lag.trend(measured)) trend.add({std::uint64_t(p.frame), p.ratio, p.tracked});
        writeFileAtomic(a.csv, trend.csv());
    }
    fmt::print("{}", a.json ? t.json().dump(2) + "\n" : t.console());
    if (!a.csv.empty() && !a.json) fmt::print("the last frame's particles' light in every frame: {}\n", a.csv);
}

}  // namespace

void addLagCommand(CLI::App& app) {
    auto args = std::make_shared<LagArgs>();
    CLI::App* cmd = app.add_subcommand(
        "lag", "The lag of a per-particle history on exact frames: the bias its average makes where nothing is noisy");
    cmd->add_option("frames", args->frames, "The frames, a {frame} pattern (e.g. 'ref.{frame}.exr': render's EXRs, with particle.id)")
        ->required();
    cmd->add_option("--frames", args->range, "A:B, half-open: the frames averaged, the last one measured")->required();
    cmd->add_option("--history", args->history, "h: the weight of the last frame's average (several: one row each; default 0.95)")
        ->delimiter(',')
        ->check(finiteIn(0.0, 0.999999));
    cmd->add_option("--start", args->start, "How a particle's average starts: first (its first frame) or mean (a running mean "
                                            "until 1 / n < 1 - h, particle_split.history_start mean; the default)");
    cmd->add_option("--layer", args->layer, "The light averaged (default Lr: the lighting alone; \"\" for R,G,B)");
    cmd->add_option("--subtract", args->subtract,
                    "A {frame} pattern whose light each frame's loses before the average (e.g. a render of the near lights "
                    "alone, particle_split.far=0: the far light, which history_of far averages); the errors stay relative "
                    "to the whole light");
    cmd->add_option("--windows-of", args->windowsOf,
                    "Measure the pixels of these EXRs' data windows alone (crops of the frame, e.g. bias's references); "
                    "the histories follow the whole frames");
    cmd->add_option("--csv", args->csv, "Write the last frame's particles' light in every frame, over their light now (CSV)");
    cmd->add_flag("--json", args->json, "Machine-readable output");
    cmd->add_flag("-q,--quiet", args->quiet, "No progress on stderr");
    cmd->footer("Each pixel is its particle's mean over its pixels, now and in its history: what one texel a particle "
                "shows.\nenergy %: the history's light less the light now, over the whole light now (--subtract: before it); relMSE: per pixel, "
                "as compare measures it, against the whole light.");
    cmd->callback([args] { runLag(*args); });
}

}  // namespace accretion::cmd
