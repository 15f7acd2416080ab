#include <catch2/catch.hpp>

#include <cmath>

#include "accretion/particles/blackbody.h"
#include "accretion/particles/disk_generator.h"

using namespace accretion;

TEST_CASE("disk generator is deterministic and inside its bounds", "[particles]") {
    ParticleSettings s;
    s.count = 5000;
    const Particles a = generateDisk(s, 3), b = generateDisk(s, 3);
    REQUIRE(a.position == b.position);
    REQUIRE(a.emission == b.emission);
    for (std::size_t i = 0; i < a.size(); ++i) {
        const float r = std::hypot(a.position[i].x, a.position[i].z);
        REQUIRE(r >= float(s.inner_radius) * 0.9999f);
        REQUIRE(r <= float(s.outer_radius) * 1.0001f);
        REQUIRE(a.radius[i] > 0.0f);
        REQUIRE(a.emission[i].x >= 0.0f);
    }
    s.seed = 2;
    REQUIRE(generateDisk(s, 3).position != a.position);
}

TEST_CASE("particle k does not depend on the count", "[particles]") {
    ParticleSettings s;
    s.count = 100;
    const Particles small = generateDisk(s, 1);
    s.count = 1000;
    const Particles large = generateDisk(s, 1);
    for (std::size_t i = 0; i < small.size(); ++i) REQUIRE(small.position[i] == large.position[i]);
}

TEST_CASE("Keplerian motion: angular speed sqrt(GM/r^3), radius and height kept", "[particles]") {
    ParticleSettings s;
    s.count = 200;
    s.time_step = 0.01;
    const Particles f0 = generateDisk(s, 0), f5 = generateDisk(s, 5);
    const double t = 5 * s.time_step;
    for (std::size_t i = 0; i < f0.size(); ++i) {
        const double r = std::hypot(f0.position[i].x, f0.position[i].z);
        const double a0 = std::atan2(f0.position[i].z, f0.position[i].x);
        const double a5 = std::atan2(f5.position[i].z, f5.position[i].x);
        const double moved = std::remainder(a5 - a0, 2.0 * M_PI);
        REQUIRE(moved == Approx(std::sqrt(s.gm / (r * r * r)) * t).epsilon(1e-3));
        REQUIRE(f5.position[i].y == f0.position[i].y);
        // Velocity: tangential, |v| = sqrt(GM / r).
        REQUIRE(glm::length(f0.velocity[i]) == Approx(std::sqrt(s.gm / r)).epsilon(1e-3));
        REQUIRE(std::fabs(glm::dot(glm::normalize(f0.velocity[i]), glm::normalize(f0.position[i] * Vec3(1, 0, 1)))) < 1e-4);
    }
}

TEST_CASE("temperature profile, types by band, blackbody colours", "[particles]") {
    ParticleSettings s;
    REQUIRE(diskTemperature(s, s.inner_radius) == Approx(s.inner_temperature));
    REQUIRE(diskTemperature(s, 16.0 * s.inner_radius) == Approx(s.inner_temperature / 8.0));  // 16^-3/4
    REQUIRE(temperatureType(s, 3000.0) == 0);
    REQUIRE(temperatureType(s, 6000.0) == 1);
    REQUIRE(temperatureType(s, 20000.0) == 2);
    // Luminance 1; cool is red, hot is blue, ~6500 K near white.
    for (double T : {2000.0, 6500.0, 30000.0}) REQUIRE(luminance(blackbodyColor(T)) == Approx(1.0f).epsilon(1e-5));
    const Vec3 cool = blackbodyColor(2000.0), hot = blackbodyColor(30000.0), white = blackbodyColor(6500.0);
    REQUIRE(cool.x > cool.z);
    REQUIRE(hot.z > hot.x);
    REQUIRE(white.x == Approx(white.z).epsilon(0.15));
    const BlackbodyTable table;
    for (double T : {1000.0, 4321.0, 12000.0}) {
        const Vec3 a = table(T), b = blackbodyColor(T);
        for (int c = 0; c < 3; ++c) REQUIRE(a[c] == Approx(b[c]).epsilon(1e-2).margin(1e-3));
    }
    // A table of a disk's range reads as the whole table, bit for bit, inside
    // the range and outside it (where its entries are computed when asked).
    const auto [lo, hi] = diskTemperatureRange(s);
    REQUIRE(lo == Approx(diskTemperature(s, s.outer_radius)));
    REQUIRE(hi == Approx(s.inner_temperature));
    const BlackbodyTable part(lo, hi);
    for (double T : {100.0, 500.0, 1000.0, 0.999 * lo, lo, std::sqrt(lo * hi), hi, 1.001 * hi, 30000.0, 1e6, 2e6}) {
        INFO(T);
        const Vec3 a = part(T), b = table(T);
        for (int c = 0; c < 3; ++c) REQUIRE(a[c] == b[c]);
    }
    // Emission luminance follows luminosity (T/T_in)^4.
    s.count = 50;
    const Particles p = generateDisk(s, 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double r = std::hypot(p.position[i].x, p.position[i].z);
        const double T = diskTemperature(s, r);
        REQUIRE(luminance(p.emission[i]) == Approx(s.luminosity * std::pow(T / s.inner_temperature, 4)).epsilon(2e-2));
        REQUIRE(p.type[i] == temperatureType(s, T));
    }
}
