// accretion plan: the passes a scene's frames run, and why the others are skipped.
#include <memory>

#include <fmt/core.h>

#include "accretion/particles/particle_source.h"
#include "accretion/render/frame_plan.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

void runPlan(const SceneArgs& a) {
    const Settings s = loadSceneArgs(a);
    // The plan needs to know whether the particles emit: load the first frame's.
    FrameFacts facts;
    facts.emissive = emissive(ParticleSource(s).frame(s.render.frame_start));
    const FramePlan first = planFrame(s, facts);
    fmt::print("{}: {} frame{} from {}, estimator {}, {}x{}\n", s.scenePath, s.render.frames, s.render.frames > 1 ? "s" : "",
               s.render.frame_start, enumName(s.render.estimator), s.camera.width, s.camera.height);
    if (s.render.frames == 1) {
        fmt::print("{}", formatPlan(first));
        return;
    }
    // Later frames find the static geometry built and the history kept.
    facts.geometryBuilt = true;
    facts.historyAvailable = first.keepHistory;
    const FramePlan later = planFrame(s, facts);
    const std::uint32_t begin = s.render.frame_start, end = begin + s.render.frames;
    if (later.passes() == first.passes()) {
        fmt::print("frames {}:{}\n{}", begin, end, formatPlan(first));
        return;
    }
    fmt::print("frame {}\n{}frames {}:{}\n{}", begin, formatPlan(first), begin + 1, end, formatPlan(later));
}

}  // namespace

void addPlanCommand(CLI::App& app) {
    auto args = std::make_shared<SceneArgs>();
    CLI::App* cmd = app.add_subcommand("plan", "Print the passes a scene's frames run, with the reason for every pass skipped");
    addSceneOptions(cmd, *args, "Frames A:B (= render.frame_start, render.frames)", false);
    cmd->callback([args] { runPlan(*args); });
}

}  // namespace accretion::cmd
