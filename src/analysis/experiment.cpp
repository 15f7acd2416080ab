#include "accretion/analysis/experiment.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/scene/scene_parser.h"

namespace accretion {

std::vector<EstimatorSpec> parseEstimatorSpecs(const std::string& list, const std::string& option) {
    std::vector<EstimatorSpec> specs;
    for (const std::string& entry : splitList(list, ',')) {
        auto fail = [&](const std::string& why) {
            throw InputError(fmt::format("command line {} '{}': {}", option, entry, why));
        };
        if (entry.empty()) fail("empty estimator");
        const auto parts = splitList(entry, ':');
        EstimatorSpec spec;
        spec.label = entry;
        if (!parseEnum(parts[0], spec.kind))
            fail(fmt::format("unknown estimator ({})", enumChoices<EstimatorKind>()));
        const std::string flag = fmt::format("{} {}", option, entry);
        spec.settings.push_back({"render.estimator", flag, [k = spec.kind](Settings& s) { s.render.estimator = k; }});
        for (std::size_t k = 1; k < parts.size(); ++k) {
            const std::string& o = parts[k];
            BiasCorrection bc;
            LightSource src;
            if (o.find('=') != std::string::npos) {
                spec.overrides.push_back(o);
            } else if (o == "basic+vis") {
                spec.settings.push_back({"restir.bias_correction", flag, [](Settings& s) { s.restir.bias_correction = BiasCorrection::basic; }});
                spec.settings.push_back({"restir.basic_visibility", flag, [](Settings& s) { s.restir.basic_visibility = true; }});
            } else if (parseEnum(o, bc)) {
                if (!estimatorInfo(spec.kind).reuse) fail("a bias correction applies to restir only");
                spec.settings.push_back({"restir.bias_correction", flag, [bc](Settings& s) { s.restir.bias_correction = bc; }});
            } else if (parseEnum(o, src)) {
                spec.settings.push_back({"render.source", flag, [src](Settings& s) { s.render.source = src; }});
            } else {
                fail(fmt::format("unknown option '{}' (none, basic, basic+vis, pairwise, uniform, power, tree, tiles, regir or key=value)", o));
            }
        }
        specs.push_back(std::move(spec));
    }
    return specs;
}

Settings specSettings(const std::filesystem::path& scene, const std::vector<std::string>& defines,
                      const std::vector<FlagSetting>& base, const EstimatorSpec& spec) {
    std::vector<std::string> overrides = defines;
    overrides.insert(overrides.end(), spec.overrides.begin(), spec.overrides.end());
    std::vector<FlagSetting> flags = base;
    flags.insert(flags.end(), spec.settings.begin(), spec.settings.end());
    return loadScene(scene, overrides, flags);
}

std::uint32_t steadyStateHistory(const Settings& settings) {
    constexpr std::uint32_t kAtLeast = 8;
    const LightingPasses passes = estimatorInfo(settings.render.estimator).passes;
    if (passes == LightingPasses::voxelCache)  // the cells' running mean to its cap
        return settings.voxel.history > 1.0 ? std::max(kAtLeast, static_cast<std::uint32_t>(std::ceil(settings.voxel.history))) : 0;
    if (passes == LightingPasses::particleSplit) {  // the texels' average, until the first frame weighs under 1%
        const ParticleSplitSettings& p = settings.particle_split;
        const double h = p.history;
        if (h <= 0.0) return 0;
        if (p.history_start == HistoryStart::first)  // h^n
            return std::max(kAtLeast, static_cast<std::uint32_t>(std::ceil(std::log(0.01) / std::log(h))));
        // A running mean (sumSplitTexel): a frame of S far rays weighs
        // max(1 - h, S / age) where age counts the far rays averaged, the
        // first frame's far_new of them if set. Frame 0 has no last frame,
        // so far_prior adds nothing to it.
        const double S = std::max(p.far, 1u);
        double age = p.far_new > 0 ? p.far_new : S, first = 1.0;
        std::uint32_t n = 0;
        for (; first >= 0.01; ++n) {
            age += S;
            first *= 1.0 - std::max(1.0 - h, S / age);
        }
        return std::max(kAtLeast, n);
    }
    if (!estimatorInfo(settings.render.estimator).reuse || !settings.restir.temporal) return 0;
    return std::max(kAtLeast, static_cast<std::uint32_t>(std::ceil(settings.restir.m_cap)));
}

HistoryChoice HistoryChoice::parse(const std::string& text) {
    if (text == "steady") return {};
    const auto n = parseUnsigned(text);
    if (!n || *n > 0xfffffffeu)
        throw InputError(fmt::format("command line --history {}: expected \"steady\" or a number of frames", text));
    return {static_cast<std::uint32_t>(*n)};
}

std::uint32_t HistoryChoice::of(const Settings& settings) const {
    if (!estimatorInfo(settings.render.estimator).reuse) return 0;
    return frames ? *frames : steadyStateHistory(settings);
}

std::string HistoryChoice::label() const { return frames ? std::to_string(*frames) : std::string("steady"); }

std::uint32_t historyBefore(const HistoryChoice& history, const Settings& settings, std::uint32_t frame, std::string_view what) {
    const std::uint32_t h = history.of(settings);
    if (h > frame)
        throw InputError(fmt::format(
            "command line --history {}: {} needs {} history frames before frame {} ({}), and frames start at 0: measure frame "
            "{} or later (--frame, with a reference of that frame) or give --history {}",
            history.label(), what, h, frame,
            history.frames                               ? std::string("as asked")
            : estimatorInfo(settings.render.estimator).passes == LightingPasses::voxelCache
                ? fmt::format("the cells' running mean to voxel.history = {:g}, at least 8", settings.voxel.history)
            : estimatorInfo(settings.render.estimator).passes == LightingPasses::particleSplit
                ? fmt::format("the texels' average with particle_split.history = {:g} until the first frame weighs under 1%, at least 8",
                              settings.particle_split.history)
                : fmt::format("temporal reuse to its M cap of {:g}, at least 8", settings.restir.m_cap),
            h,
            frame));
    return h;
}

namespace {

/// Set the frames rendered to `frame`'s history and `frame` (restir's
/// history frames first, so that the pass plan keeps its history; none
/// without reuse); returns the first frame rendered.
std::uint32_t renderFramesUpTo(Settings& run, std::uint32_t frame, std::uint32_t history) {
    const std::uint32_t first = estimatorInfo(run.render.estimator).reuse ? frame - std::min(frame, history) : frame;
    run.render.frame_start = first;
    run.render.frames = frame - first + 1;
    return first;
}

}  // namespace

ExperimentRender renderForExperiment(const Settings& settings, const ParticleSource& source, std::uint32_t frame,
                                     std::uint32_t history) {
    ExperimentRender r;
    Settings run = settings;
    const std::uint32_t first = renderFramesUpTo(run, frame, history);
    FrameRenderer renderer(run, source, RenderOptions{true});
    const auto start = std::chrono::steady_clock::now();
    for (std::uint32_t f = first;; ++f) {  // to `frame` inclusive, which may be the last 32-bit number
        FrameStats stats;
        r.image = renderer.render(f, stats);
        if (f == frame) {
            r.frameSeconds = stats.seconds;
            r.stats = std::move(stats);
            break;
        }
    }
    r.totalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

std::vector<ExperimentRender> renderLanesForExperiment(std::vector<Settings> lanes, const ParticleSource& source,
                                                       std::uint32_t frame, std::uint32_t history) {
    std::uint32_t first = frame;
    for (Settings& run : lanes) first = renderFramesUpTo(run, frame, history);
    const std::size_t n = lanes.size();
    FrameRenderer renderer(std::move(lanes), source, RenderOptions{true});
    std::vector<ExperimentRender> r(n);
    std::vector<double> own(n, 0.0);
    const auto start = std::chrono::steady_clock::now();
    for (std::uint32_t f = first;; ++f) {  // to `frame` inclusive, which may be the last 32-bit number
        FrameStats shared;
        std::vector<FrameStats> stats;
        std::vector<FrameImage> images = renderer.renderLanes(f, shared, stats);
        double lanesSeconds = 0.0;
        for (const FrameStats& s : stats) lanesSeconds += s.seconds;
        const double geometrySeconds = std::max(0.0, shared.seconds - lanesSeconds) / double(n);
        for (std::size_t k = 0; k < n; ++k) {
            own[k] += stats[k].seconds + geometrySeconds;
            if (f != frame) continue;
            r[k].image = std::move(images[k]);
            r[k].frameSeconds = stats[k].seconds + geometrySeconds;
            r[k].stats = std::move(stats[k]);
        }
        if (f == frame) break;
    }
    // Each lane's share of the wall time: its own passes and an even share of the rest.
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double sum = 0.0;
    for (double s : own) sum += s;
    for (std::size_t k = 0; k < n; ++k) r[k].totalSeconds = sum > 0.0 ? wall * own[k] / sum : wall / double(n);
    return r;
}

}  // namespace accretion
