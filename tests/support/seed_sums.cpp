#include "support/seed_sums.h"

#include <algorithm>
#include <cmath>

#include "support/oracle.h"

namespace accretion::test {

double imageLrSum(const FrameImage& img) {
    double s = 0.0;
    for (const Vec3& v : img.lighting.Lr) s += double(v.x) + v.y + v.z;
    return s;
}

SeedSums seedImageSums(Settings s, EstimatorKind estimator, std::uint32_t frames, std::uint32_t seeds, std::uint64_t firstSeed) {
    s.render.estimator = estimator;
    s.render.frames = frames;  // the pass plan keeps the history for more than one frame
    const ParticleSource source(s);  // copies share the generator's tables
    double s1 = 0.0, s2 = 0.0;
    for (std::uint32_t seed = 0; seed < seeds; ++seed) {
        s.render.seed = firstSeed + seed;
        FrameRenderer renderer(s, source, RenderOptions{true});
        FrameImage img;
        for (std::uint32_t f = 0; f < frames; ++f) {
            FrameStats stats;
            img = renderer.render(f, stats);
        }
        const double x = imageLrSum(img);
        s1 += x;
        s2 += x * x;
    }
    SeedSums r;
    r.mean = s1 / seeds;
    r.stderr = std::sqrt(std::max(0.0, (s2 / seeds - r.mean * r.mean) / (seeds - 1.0)));
    return r;
}

double oracleImageSum(Settings s, std::uint32_t frame) {
    if (s.camera.path == CameraPath::orbit) {
        const double a = double(frame) * s.camera.orbit_speed * 3.14159265358979323846 / 180.0;
        const glm::dvec3 t(s.camera.look_at), d = glm::dvec3(s.camera.position) - t;
        s.camera.position = Vec3(t + glm::dvec3(std::cos(a) * d.x + std::sin(a) * d.z, d.y, -std::sin(a) * d.x + std::cos(a) * d.z));
        s.camera.path = CameraPath::static_pose;
    }
    const OracleImage o = oracleRender(s, ParticleSource(s).frame(frame));
    double sum = 0.0;
    for (const glm::dvec3& v : o.Lr) sum += v.x + v.y + v.z;
    return sum;
}

}  // namespace accretion::test
