#include <catch2/catch.hpp>

#include "accretion/particles/particle_file.h"
#include "accretion/particles/particle_source.h"
#include "support/test_scenes.h"

using namespace accretion;

TEST_CASE("per-frame files: velocity from consecutive frames, albedo from the scene", "[particles]") {
    const auto dir = accretion::test::scratchDir("particle_frames");
    Particles f0, f1, f2;
    f0.push(Vec3(0.0f), 1.0f, Vec3(1.0f));
    f1.push(Vec3(1.0f, 0.0f, 0.0f), 1.0f, Vec3(1.0f));
    f2.push(Vec3(3.0f, 0.0f, 0.0f), 1.0f, Vec3(1.0f));
    writeParticles(dir / "p.0000.bin", f0, ParticleFormat::raw);
    writeParticles(dir / "p.0001.bin", f1, ParticleFormat::raw);
    writeParticles(dir / "p.0002.ply", f2, ParticleFormat::ply);
    Settings s;
    s.particles.file = (dir / "p.{frame}.bin").string();
    s.particles.time_step = 0.5;
    s.shading.albedo = Vec3(0.1f, 0.2f, 0.3f);
    const ParticleSource source(s);
    REQUIRE_FALSE(source.isStatic());
    const Particles a = source.frame(0), b = source.frame(1);
    REQUIRE(a.velocity[0] == Vec3(2.0f, 0.0f, 0.0f));  // forward difference / dt
    REQUIRE(b.velocity[0] == Vec3(2.0f, 0.0f, 0.0f));  // no frame 2 .bin: backward difference
    REQUIRE(a.albedo[0] == s.shading.albedo);
    s.particles.file = (dir / "p.0002.ply").string();
    const Particles c = ParticleSource(s).frame(7);  // no {frame}: the same file every frame
    REQUIRE(c.position[0] == Vec3(3.0f, 0.0f, 0.0f));
    REQUIRE(c.velocity[0] == Vec3(0.0f));
}
