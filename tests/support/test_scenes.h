#pragma once
#include <filesystem>
#include <string>

#include "accretion/lighting/light_tree.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/scene/settings.h"

namespace accretion::test {

/// Settings of a static camera looking down -z from (0,0,dist) at the origin,
/// odd square resolution so that the centre pixel's ray is exactly the axis.
Settings axisCameraSettings(float dist = 10.0f, std::uint32_t size = 33, double fov = 10.0);

/// A small disk seen from above at an angle: 150 particles at 48x32, visible
/// occlusion, a dmin clamp that bounds the tails of one-sample estimates (so
/// per-pixel standard errors are reliable), mild emission contrast.
Settings smallDiskSettings();

/// The small disk shaded with `model`: frame 0's particles and their light tree.
struct DiskLights {
    /// smallDiskSettings' disk, or `count` particles of it (0: its own count).
    explicit DiskLights(ShadingModel model, std::uint32_t count = 0);
    Settings settings;
    Particles particles;
    LightTree tree;
};

/// Frame 0 of `settings` traced: its particles, camera, BVH and G-buffer.
struct TracedFrame {
    explicit TracedFrame(const Settings& settings);
    Particles particles;
    Camera camera;
    EmbreeDevice device;
    ParticleBvh bvh;
    GBuffer gbuffer;
};

/// Render one frame of a fixed particle set.
FrameImage renderParticles(const Settings& settings, const Particles& particles, std::uint32_t frame = 0);

/// A fresh empty directory under the build tree for a test's files.
std::filesystem::path scratchDir(const std::string& name);

/// tests/data/small_disk.toml: a small disk filling a 96x64 image, for CLI runs.
std::string smallDiskScene();

/// A whole file's bytes.
std::string readFile(const std::filesystem::path& file);

/// The `accretion` program the command-line tests run: this build's, or the
/// environment's ACCRETION_PROGRAM (the sanitizer stage runs the Release
/// build's command-line tests against its instrumented program).
const std::string& programPath();

/// Run a shell command; returns its exit status, stdout+stderr in `output`.
int runCommand(const std::string& command, std::string& output);

/// A small generated disk and a camera looking at it (the BVH and micromap tests).
struct SmallView {
    ParticleSettings particles;
    CameraSettings camera;
};
SmallView smallView(std::uint32_t count, double outerRadius, double radius, Vec3 eye, std::uint32_t width,
                    std::uint32_t height);

}  // namespace accretion::test
