// accretion particles: write the generator's particles in the GPU's format.
#include <filesystem>
#include <memory>

#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/atomic_file.h"
#include "accretion/particles/particle_file.h"
#include "accretion/particles/particle_source.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct ParticlesArgs : SceneArgs {
    std::string out = "particles";
    std::string format = "raw";
};

void runParticles(const ParticlesArgs& args) {
    const Settings settings = loadSceneArgs(args);
    const ParticleFormat format = args.format == "ply" ? ParticleFormat::ply : ParticleFormat::raw;
    const ParticleSource source(settings);
    const std::filesystem::path dir(args.out);
    auto fileOf = [&](std::uint32_t frame) {
        return dir / fmt::format("{}.{:04d}.{}", settings.sceneName, frame, format == ParticleFormat::ply ? "ply" : "bin");
    };
    const OutputGuard guard = sceneInputs(settings);  // e.g. --out where the scene's own particle files are
    for (std::uint32_t k = 0; k < settings.render.frames; ++k) guard.check(fileOf(settings.render.frame_start + k), "--out");
    guard.check(dir / (settings.sceneName + ".settings.toml"), "--out");
    for (std::uint32_t k = 0; k < settings.render.frames; ++k) {
        const std::uint32_t frame = settings.render.frame_start + k;
        const Particles p = source.frame(frame);
        const auto file = fileOf(frame);
        writeParticles(file, p, format);
        fmt::print("{} ({} particles)\n", file.string(), p.size());
    }
    writeFileAtomic(dir / (settings.sceneName + ".settings.toml"), settingsToToml(settings));
}

}  // namespace

void addParticlesCommand(CLI::App& app) {
    auto args = std::make_shared<ParticlesArgs>();
    CLI::App* cmd = app.add_subcommand("particles", "Write a scene's particles in the GPU buffer format (32-byte records) or PLY");
    addSceneOptions(cmd, *args, "Frames A:B, half-open (default: the scene's render frames)", false);
    cmd->add_option("--out", args->out, "Output directory (files <scene>.<frame>.bin|ply)");
    cmd->add_option("--format", args->format, "raw (GPU buffer, little-endian) | ply (binary)")
        ->check(CLI::IsMember({"raw", "ply"}));
    cmd->callback([args] { runParticles(*args); });
}

}  // namespace accretion::cmd
