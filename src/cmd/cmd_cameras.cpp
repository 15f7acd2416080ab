// accretion cameras: a scene's camera of each frame as a camera file, in
// the engine's convention (to feed the engine, or to check a reader).
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/geometry/camera_track.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CamerasArgs : SceneArgs {
    std::string output, convention = "opengl";
    bool pose = false;
};

void runCameras(const CamerasArgs& a) {
    const Settings settings = loadSceneArgs(a);
    CameraConvention convention;
    if (!CameraConvention::preset(a.convention, convention))
        throw InputError(fmt::format("command line --convention {}: expected opengl, vulkan or d3d", a.convention));
    const std::uint32_t first = settings.render.frame_start, end = first + settings.render.frames;
    const OutputGuard guard = sceneInputs(settings, first, end);
    guard.check(a.output, "-o");
    writeCameraFile(a.output, CameraTrack(settings.camera), settings.camera, first, end, convention, !a.pose);
    fmt::print("cameras: {} (frames {}..{}, {})\n", a.output, first, end - 1, a.pose ? "look-at poses" : a.convention + " matrices");
}

}  // namespace

void addCamerasCommand(CLI::App& app) {
    auto args = std::make_shared<CamerasArgs>();
    CLI::App* cmd = app.add_subcommand("cameras", "Write a scene's camera of each frame as a camera file (camera.file)");
    addSceneOptions(cmd, *args, "Frames A:B (= render.frame_start, render.frames)", false);
    cmd->add_option("-o,--output", args->output, "Camera file (JSON)")->required();
    cmd->add_option("--convention", args->convention, "Matrix convention: opengl (default), vulkan, d3d");
    cmd->add_flag("--pose", args->pose, "Eye, look_at, up, fov instead of view and projection matrices");
    cmd->callback([args] { runCameras(*args); });
}

}  // namespace accretion::cmd
