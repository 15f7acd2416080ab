#include <catch2/catch.hpp>

#include <algorithm>

#include "accretion/geometry/clustering.h"
#include "accretion/particles/disk_generator.h"

using namespace accretion;

TEST_CASE("clusters partition the particles, none above the target size", "[geometry]") {
    ParticleSettings s;
    s.count = GENERATE(1u, 99u, 5000u, 20000u);
    const std::uint32_t target = GENERATE(1u, 64u, 100u);
    const Particles p = generateDisk(s, 0);
    const Clusters c = clusterParticles(p.position, target);
    std::vector<std::uint32_t> all = c.particle;
    std::sort(all.begin(), all.end());
    for (std::uint32_t i = 0; i < s.count; ++i) REQUIRE(all[i] == i);
    REQUIRE(c.offset.back() == s.count);
    std::size_t maxSize = 0;
    for (std::size_t k = 0; k < c.count(); ++k) {
        REQUIRE(c.members(k).size() >= 1);
        maxSize = std::max(maxSize, c.members(k).size());
    }
    REQUIRE(maxSize <= target);
    // Clusters are not degenerate: on average at least a quarter full.
    if (s.count >= 100 * target) REQUIRE(double(s.count) / double(c.count()) >= 0.25 * target);
    REQUIRE(clusterParticles(p.position, target).particle == c.particle);  // deterministic
}

TEST_CASE("clusters are spatially compact", "[geometry]") {
    ParticleSettings s;
    s.count = 20000;
    const Particles p = generateDisk(s, 0);
    const Clusters c = clusterParticles(p.position, 100);
    // Mean cluster bounding-box diagonal far below the disk's size.
    double sum = 0.0;
    for (std::size_t k = 0; k < c.count(); ++k) {
        Vec3 lo(1e30f), hi(-1e30f);
        for (std::uint32_t i : c.members(k)) {
            lo = glm::min(lo, p.position[i]);
            hi = glm::max(hi, p.position[i]);
        }
        sum += glm::length(hi - lo);
    }
    REQUIRE(sum / double(c.count()) < 0.15 * 2.0 * s.outer_radius);
}
