#include "support/test_scenes.h"

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

#include "accretion/particles/particle_source.h"

namespace accretion::test {

Settings axisCameraSettings(float dist, std::uint32_t size, double fov) {
    Settings s;
    s.camera.position = Vec3(0.0f, 0.0f, dist);
    s.camera.look_at = Vec3(0.0f);
    s.camera.up = Vec3(0.0f, 1.0f, 0.0f);
    s.camera.fov = fov;
    s.camera.width = s.camera.height = size;
    s.render.estimator = EstimatorKind::exact;
    return s;
}

Settings smallDiskSettings() {
    Settings s;
    s.particles.count = 150;
    s.particles.temperature_exponent = 0.25;
    s.particles.inner_radius = 0.5;
    s.particles.outer_radius = 2.0;
    s.particles.thickness = 0.2;
    s.particles.radius = 0.08;
    s.particles.seed = 7;
    s.camera.position = Vec3(0.0f, 2.5f, 3.5f);
    s.camera.width = 48;
    s.camera.height = 32;
    s.camera.fov = 50.0;
    s.shading.dmin = 0.4;
    return s;
}

DiskLights::DiskLights(ShadingModel model, std::uint32_t count)
    : settings([model, count] {
          Settings s = smallDiskSettings();
          s.shading.model = model;
          if (count > 0) s.particles.count = count;
          return s;
      }()),
      particles(ParticleSource(settings).frame(0)),
      tree(particles, settings.shading) {}

TracedFrame::TracedFrame(const Settings& settings)
    : particles(ParticleSource(settings).frame(0)), camera(Camera::atFrame(settings.camera, 0)), bvh(device, settings.geometry) {
    bvh.build(particles, camera);
    traceGBuffer(bvh, particles, camera, settings.shading.model, gbuffer);
}

FrameImage renderParticles(const Settings& settings, const Particles& particles, std::uint32_t frame) {
    FrameRenderer renderer(settings, ParticleSource::fixed(particles), RenderOptions{true});
    FrameStats stats;
    return renderer.render(frame, stats);
}

std::filesystem::path scratchDir(const std::string& name) {
    const auto dir = std::filesystem::current_path() / "scratch" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::string smallDiskScene() { return std::string(ACCRETION_SOURCE_DIR) + "/tests/data/small_disk.toml"; }

std::string readFile(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

const std::string& programPath() {
    static const std::string path = [] {
        const char* program = std::getenv("ACCRETION_PROGRAM");
        return std::string(program && *program ? program : ACCRETION_BINARY);
    }();
    return path;
}

int runCommand(const std::string& command, std::string& output) {
    output.clear();
    FILE* pipe = popen((command + " 2>&1").c_str(), "r");
    if (!pipe) return -1;
    std::array<char, 4096> buf;
    while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) output.append(buf.data(), n);
    const int status = pclose(pipe);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

SmallView smallView(std::uint32_t count, double outerRadius, double radius, Vec3 eye, std::uint32_t width,
                    std::uint32_t height) {
    SmallView v;
    v.particles.count = count;
    v.particles.outer_radius = outerRadius;
    v.particles.radius = radius;
    v.camera.position = eye;
    v.camera.width = width;
    v.camera.height = height;
    return v;
}

}  // namespace accretion::test
