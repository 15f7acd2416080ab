#pragma once
#include <optional>
#include <string_view>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "accretion/render/frame_renderer.h"
#include "accretion/scene/scene_parser.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// One estimator variant of an experiment, from `--estimators`:
/// name[:option...] where an option is a restir bias correction (none,
/// basic, pairwise, basic+vis), a candidate source (uniform, power) or a
/// setting override key=value. Examples: `uniform`, `ris:power`,
/// `restir:pairwise`, `restir:none:restir.m_cap=5`.
struct EstimatorSpec {
    std::string label;                   ///< the spec as written
    EstimatorKind kind = EstimatorKind::uniform;
    std::vector<FlagSetting> settings;   ///< the estimator, bias correction, source it sets
    std::vector<std::string> overrides;  ///< its key=value options, as -D
};

/// Parse a comma-separated list; errors name `option` and the bad entry.
std::vector<EstimatorSpec> parseEstimatorSpecs(const std::string& list, const std::string& option);

/// The scene's settings for one spec: the scene's -D overrides and the
/// spec's key=value options, then the base flags (--frames), then the spec's settings.
Settings specSettings(const std::filesystem::path& scene, const std::vector<std::string>& defines,
                      const std::vector<FlagSetting>& base, const EstimatorSpec& spec);

/// The result of rendering one frame for an experiment.
struct ExperimentRender {
    FrameImage image;
    FrameStats stats;           ///< of the measured (last) frame
    double frameSeconds = 0.0;  ///< wall time of the measured frame
    double totalSeconds = 0.0;  ///< including restir's history frames
};

/// The history frames that bring an estimator's reuse to steady state, as
/// the engine runs it: for temporal reuse until the history's M cap
/// saturates (a reservoir gains the current M a frame, up to m_cap times
/// it: ceil(m_cap) frames); the voxel cache's running mean to
/// voxel.history; particle_split's texel average until its first frame
/// weighs under 1% (h^n, or from a running mean 1/(n+1) until that falls
/// to 1 - h, the first frame counting far_new rays where set); each at
/// least 8; none without reuse (nothing of a frame carries over to the
/// next).
std::uint32_t steadyStateHistory(const Settings& settings);

/// --history: "steady" (steadyStateHistory of each configuration) or a
/// number of frames; throws InputError naming the flag otherwise.
struct HistoryChoice {
    std::optional<std::uint32_t> frames;  ///< none: steady state
    static HistoryChoice parse(const std::string& text);
    /// The frames rendered before the measured one: none for an estimator
    /// without reuse (nothing carries over), else the number asked or the
    /// steady state's.
    std::uint32_t of(const Settings& settings) const;
    std::string label() const;  ///< "steady" or the number
};

/// The history frames of `settings` measured at `frame`: history.of(settings),
/// refused (InputError naming --history and --frame) where fewer frames
/// than that come before `frame`: a measurement short of its history is
/// not the one asked for.
std::uint32_t historyBefore(const HistoryChoice& history, const Settings& settings, std::uint32_t frame, std::string_view what);

/// Render `frame` with the settings; restir first renders the `history`
/// frames before it (frame - history .. frame - 1, clamped at 0), so its
/// temporal reuse is in steady state as on the GPU.
ExperimentRender renderForExperiment(const Settings& settings, const ParticleSource& source, std::uint32_t frame,
                                     std::uint32_t history);

/// The same for several lanes of one scene (settings that differ only in
/// render.seed, render.crop and restir.crop_margin: FrameRenderer's lanes),
/// each frame's geometry built once for all of them. Each lane's image is
/// the one renderForExperiment gives it; its times are its own passes plus
/// an even share of the geometry's, and its stats its own passes'.
std::vector<ExperimentRender> renderLanesForExperiment(std::vector<Settings> lanes, const ParticleSource& source,
                                                       std::uint32_t frame, std::uint32_t history);

}  // namespace accretion
