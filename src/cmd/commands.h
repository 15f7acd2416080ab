#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

namespace accretion::cmd {

/// Options shared by the commands that load a scene.
struct SceneArgs {
    std::string scene;                   ///< scene file
    std::vector<std::string> defines;    ///< -D section.key=value
    std::string frames;                  ///< --frames A:B (half-open)
    int threads = 0;                     ///< --threads N (0: all cores)
    bool quiet = false;                  ///< --quiet: no progress on stderr
};

/// Thrown by batch when some job did not succeed (exit code 4).
struct BatchFailed {};

/// Parse `A:B` (half-open, 0 <= A < B) or `A` (= A:A+1) of a command-line
/// option; InputError names the option.
std::pair<std::uint64_t, std::uint64_t> parseHalfOpen(const std::string& text, const char* option);

/// Turn `--frames A:B` into overrides of render.frame_start / render.frames.
void appendFrameOverrides(const std::string& frames, std::vector<std::string>& overrides);

void addRenderCommand(CLI::App& app);
void addParticlesCommand(CLI::App& app);
void addCompareCommand(CLI::App& app);
void addConvergeCommand(CLI::App& app);
void addBiasCommand(CLI::App& app);
void addCostCommand(CLI::App& app);
void addCalibrateCommand(CLI::App& app);
void addPlanCommand(CLI::App& app);
void addMergeCommand(CLI::App& app);
void addBatchCommand(CLI::App& app);

}  // namespace accretion::cmd
