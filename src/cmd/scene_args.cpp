// What the commands that load a scene share: its options, the flags that
// set typed settings, the thread limit.
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/particles/particle_source.h"
#include "commands.h"

namespace accretion::cmd {

Settings loadSceneArgs(const SceneArgs& a, const std::vector<FlagSetting>& flags) {
    std::vector<FlagSetting> all = frameFlags(a.frames);
    all.insert(all.end(), flags.begin(), flags.end());
    return loadScene(a.scene, a.defines, all);
}

OutputGuard sceneInputs(const Settings& settings, std::uint32_t first, std::uint32_t end) {
    OutputGuard guard;
    guard.addInput(settings.scenePath);
    for (const auto& f : ParticleSource(settings).checkFiles(first, end)) guard.addInput(f);
    const std::vector<std::uint32_t> missing = CameraTrack(settings.camera).missing(first, end);
    if (!missing.empty())
        throw InputError(fmt::format("{}: no camera for frame {} (frames {}..{} of this run are checked before the first "
                                     "renders)", settings.camera.file, missing.front(), first, end - 1));
    guard.addInput(settings.camera.file);
    return guard;
}

OutputGuard sceneInputs(const Settings& settings) {
    const std::uint32_t first = settings.render.frame_start;
    return sceneInputs(settings, first, first + settings.render.frames);
}

void checkOutputs(const OutputGuard& guard, const std::string& prefix, const std::vector<std::string>& suffixes,
                  std::string_view what) {
    for (const std::string& s : suffixes) guard.check(prefix + s, what);
}

std::unique_ptr<tbb::global_control> limitThreads(int threads) {
    if (threads <= 0) return nullptr;
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
}

CLI::Validator finiteIn(double lo, double hi) {
    return CLI::Validator(
        [lo, hi](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
                return fmt::format("{}: expected a finite number from {} to {}", text, lo, hi);
            return {};
        },
        fmt::format("FINITE in [{} - {}]", lo, hi));
}

CLI::Validator unsignedNumber() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
                return fmt::format("{}: expected a whole number of 0 or more, without a sign", text);
            return {};
        },
        "UINT");
}

void addSceneOptions(CLI::App* cmd, SceneArgs& args, const std::string& framesHelp, bool threadsAndQuiet) {
    cmd->add_option("scene", args.scene, "Scene file (TOML)")->required();
    cmd->add_option("--frames", args.frames, framesHelp);
    cmd->add_option("-D,--define", args.defines, "Override a setting: -D section.key=value (TOML value)")->allow_extra_args(false);
    if (!threadsAndQuiet) return;
    cmd->add_option("--threads", args.threads, "Worker threads (default: all cores); never changes the results")
        ->check(CLI::Range(0, 4096));
    cmd->add_flag("-q,--quiet", args.quiet, "No progress on stderr");
}

void addExperimentOptions(CLI::App* cmd, ExperimentArgs& args, const std::string& referenceHelp,
                          const std::string& estimatorsHelp, const std::string& outHelp) {
    addSceneOptions(cmd, args, "Frames A:B (= render.frame_start, render.frames); the first is measured");
    cmd->add_option("--reference", args.references, referenceHelp)->required()->allow_extra_args(false);
    cmd->add_option("--estimators", args.estimators, estimatorsHelp);
    cmd->add_option("--frame", args.frame, "Frame measured (default render.frame_start)")
        ->check(unsignedNumber())
        ->check(CLI::Range(0u, 0xfffffffeu));
    cmd->add_option("--history", args.history,
                    "restir: frames rendered before the measured one: steady (default: with temporal reuse until its M cap "
                    "saturates, ceil(restir.m_cap) frames and at least 8; none without) or a number");
    cmd->add_option("-o,--out", args.out, outHelp);
}

void requireHistories(const ExperimentArgs& args, const std::vector<FlagSetting>& base, const std::vector<EstimatorSpec>& specs,
                      std::uint32_t frame) {
    const HistoryChoice history = HistoryChoice::parse(args.history);
    for (const EstimatorSpec& spec : specs) historyBefore(history, specSettings(args.scene, args.defines, base, spec), frame, spec.label);
}

void requireWholeImage(const Settings& settings, std::string_view command) {
    if (!settings.render.crop.empty())
        throw InputError(fmt::format("{}: render.crop: {} measures whole images; render a window with `accretion render --crop`",
                                     settings.scenePath.empty() ? std::string("command line") : settings.scenePath, command));
}

}  // namespace accretion::cmd
