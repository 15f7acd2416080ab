#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include "accretion/analysis/experiment.h"
#include "accretion/core/output_guard.h"
#include "accretion/scene/scene_parser.h"

namespace accretion::cmd {

/// Options shared by the commands that load a scene.
struct SceneArgs {
    std::string scene;                   ///< scene file
    std::vector<std::string> defines;    ///< -D section.key=value
    std::string frames;                  ///< --frames A:B (half-open)
    int threads = 0;                     ///< --threads N (0: all cores)
    bool quiet = false;                  ///< --quiet: no progress on stderr
};

/// Options of the experiment commands (converge, bias): a scene measured
/// against a reference, per estimator spec, over seeds.
struct ExperimentArgs : SceneArgs {
    std::vector<std::string> references;  ///< --reference (bias: one per crop of the view; converge: one)
    std::string estimators, out;
    const std::string& reference() const { return references.front(); }
    std::string history = "steady";  ///< --history: "steady" or frames (HistoryChoice)
    std::uint32_t seeds = 1;
    std::optional<std::uint32_t> frame;
};

/// Adds the scene options and --reference, --estimators, --frame, --history, -o,--out.
void addExperimentOptions(CLI::App* cmd, ExperimentArgs& args, const std::string& referenceHelp,
                          const std::string& estimatorsHelp, const std::string& outHelp);

/// Before any work: every spec's --history fits before `frame` (historyBefore).
void requireHistories(const ExperimentArgs& args, const std::vector<FlagSetting>& base, const std::vector<EstimatorSpec>& specs,
                      std::uint32_t frame);

/// Thrown by batch when some job did not succeed (exit code 4).
struct BatchFailed {};

/// The command's scene: the file, its -D overrides, --frames, then `flags`.
Settings loadSceneArgs(const SceneArgs& args, const std::vector<FlagSetting>& flags = {});

/// Experiments measure whole images: refuse render.crop (only render, and
/// its --pixel, take a window).
void requireWholeImage(const Settings& settings, std::string_view command);

/// The scene's own files as inputs no output may replace, checked before
/// anything renders: the scene, every particle file frames [first, end)
/// read (the whole {frame} sequence: exists, valid, one count) and the
/// camera file (a camera for every frame). Without a range: the scene's
/// render.frames.
OutputGuard sceneInputs(const Settings& settings, std::uint32_t first, std::uint32_t end);
OutputGuard sceneInputs(const Settings& settings);

/// Before any work: refuse each `prefix + suffix` that `guard` refuses.
void checkOutputs(const OutputGuard& guard, const std::string& prefix, const std::vector<std::string>& suffixes,
                  std::string_view what);

/// --threads N as a TBB limit for the life of the result (none for 0).
std::unique_ptr<tbb::global_control> limitThreads(int threads);

/// A number option's check: finite and in [lo, hi] (CLI::Range lets NaN
/// through, since every comparison with it is false).
CLI::Validator finiteIn(double lo, double hi);
/// An unsigned option's check: no sign (CLI11 reads "-1" into an unsigned
/// option as 2^64 - 1).
CLI::Validator unsignedNumber();

/// The options of SceneArgs: scene, --frames (with its help), -D, and
/// optionally --threads and --quiet.
void addSceneOptions(CLI::App* cmd, SceneArgs& args, const std::string& framesHelp, bool threadsAndQuiet = true);


void addRenderCommand(CLI::App& app);
void addParticlesCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addConvergeCommand(CLI::App& app);
void addBiasCommand(CLI::App& app);
void addCostCommand(CLI::App& app);
void addCalibrateCommand(CLI::App& app);
void addPlanCommand(CLI::App& app);
void addEstimatorsCommand(CLI::App& app);
void addPassesCommand(CLI::App& app);
void addMergeCommand(CLI::App& app);
void addBatchCommand(CLI::App& app);
void addCamerasCommand(CLI::App& app);
void addImportGpuCommand(CLI::App& app);
void addTuneCommand(CLI::App& app);
void addLagCommand(CLI::App& app);

}  // namespace accretion::cmd
