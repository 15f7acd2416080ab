// The split estimator's near field: LightTree::nearest finds the k nearest
// lights (checked against a brute-force sort of the distances) and the
// receiver's own, keeps them in tree order with their powers, and the far
// pdf (LightTree::pdfFar) is 0 on them and sums to 1 over the rest, with
// every lit far light drawable.
#include <algorithm>
#include <numeric>

#include <catch2/catch.hpp>

#include "accretion/lighting/light_tree.h"
#include "accretion/particles/particle_source.h"
#include "support/test_scenes.h"

using namespace accretion;

namespace {

ShadingPoint receiverOn(const Particles& particles, std::uint32_t j, const Vec3& n) {
    return ShadingPoint{particles.position[j], glm::normalize(n), Vec3(0, 1, 0), Vec3(0.8f), j, particles.position[j], Vec3(0.0f)};
}

}  // namespace

TEST_CASE("nearest: the k nearest lights but the receiver's own, against a brute-force sort", "[lighting][nearfield]") {
    Settings s = accretion::test::smallDiskSettings();
    s.particles.count = 400;
    const Particles particles = ParticleSource(s).frame(0);
    const LightTree tree(particles, s.shading);
    const auto N = static_cast<std::uint32_t>(particles.size());
    NearField near;
    for (const std::uint32_t j : {0u, 3u, 77u, 211u, N - 1}) {
        const ShadingPoint sp = receiverOn(particles, j, Vec3(0.3f, 1.0f, 0.2f));
        // Every other light by distance (the brute force shares nothing with the tree).
        std::vector<std::pair<double, std::uint32_t>> all;
        for (std::uint32_t i = 0; i < N; ++i)
            if (i != j) all.push_back({glm::distance(glm::dvec3(particles.position[i]), glm::dvec3(sp.x)), i});
        std::sort(all.begin(), all.end());
        // nearestLights: one search, nearest first; the split pilot takes its
        // first k as nearest(k)'s lights for every candidate k.
        std::uint32_t order[NearField::kMaxLights];
        const std::uint32_t found = tree.nearestLights(sp, 256, order);
        REQUIRE(found == std::min(256u, N - 1));
        for (std::uint32_t m = 1; m < found; ++m)
            CHECK(glm::distance(glm::dvec3(particles.position[order[m - 1]]), glm::dvec3(sp.x)) <=
                  glm::distance(glm::dvec3(particles.position[order[m]]), glm::dvec3(sp.x)) * (1.0 + 1e-6));
        for (const std::uint32_t k : {1u, 5u, 32u, 256u}) {
            INFO("receiver " << j << ", k " << k);
            tree.nearest(sp, k, near);
            std::vector<std::uint32_t> prefix(order, order + std::min(k, found)), search;
            for (std::uint32_t m = 0; m < near.count; ++m)
                if (near.light[m] != j) search.push_back(near.light[m]);
            std::sort(prefix.begin(), prefix.end());
            std::sort(search.begin(), search.end());
            CHECK(prefix == search);
            const std::uint32_t want = std::min(k, N - 1);
            REQUIRE(near.count == want + 1);  // and the receiver's own particle
            CHECK(near.contains(j));
            std::vector<std::uint32_t> got;
            for (std::uint32_t m = 0; m < near.count; ++m)
                if (near.light[m] != j) got.push_back(near.light[m]);
            std::sort(got.begin(), got.end());
            REQUIRE(got.size() == want);
            CHECK(std::adjacent_find(got.begin(), got.end()) == got.end());  // no light twice
            // The farthest found is no farther than the k-th by brute force
            // (a tie at the k-th distance could swap equal lights).
            double farthest = 0.0;
            for (std::uint32_t i : got) farthest = std::max(farthest, glm::distance(glm::dvec3(particles.position[i]), glm::dvec3(sp.x)));
            CHECK(farthest <= all[want - 1].first * (1.0 + 1e-6));
            std::vector<std::uint32_t> truth;
            for (std::uint32_t m = 0; m < want; ++m) truth.push_back(all[m].second);
            std::sort(truth.begin(), truth.end());
            CHECK(got == truth);
            // Tree order and the prefix sums of luminance(I).
            for (std::uint32_t m = 1; m < near.count; ++m) CHECK(near.key[m - 1] < near.key[m]);
            double power = 0.0;
            for (std::uint32_t m = 0; m < near.count; ++m) {
                const Vec3& I = particles.emission[near.light[m]];
                power += 0.2126 * I.x + 0.7152 * I.y + 0.0722 * I.z;
                CHECK(near.power[m + 1] == Approx(power).epsilon(1e-5));
            }
        }
    }
}

TEST_CASE("pdfFar: zero on the near lights, sums to 1 over the far ones, covers every lit far light", "[lighting][nearfield]") {
    const ShadingModel model = GENERATE(ShadingModel::lambert, ShadingModel::isotropic);
    INFO("model " << enumName(model));
    const accretion::test::DiskLights disk(model);
    const auto& [s, particles, tree] = disk;
    const auto N = static_cast<std::uint32_t>(particles.size());
    NearField near;
    for (const std::uint32_t j : {1u, 40u, 99u}) {
        const ShadingPoint sp = receiverOn(particles, j, Vec3(-0.2f, 1.0f, 0.4f));
        for (const std::uint32_t k : {0u, 1u, 8u, 40u, N - 2, N - 1}) {
            INFO("receiver " << j << ", k " << k);
            tree.nearest(sp, k, near);
            double sum = 0.0;
            for (std::uint32_t i = 0; i < N; ++i) {
                const double p = tree.pdfFar(sp, near, i);
                sum += p;
                if (near.contains(i) || i == j) {
                    CHECK(p == 0.0);
                    continue;
                }
                LightTerm t;
                const bool lit = evalLight(model, sp, particles.position[i], particles.emission[i],
                                           std::max(float(s.shading.dmin * s.shading.dmin), particles.radius[i] * particles.radius[i]), t);
                if (lit) CHECK(p > 0.0);  // unbiased: every far light with a term can be drawn
            }
            // With every light near, nothing is left.
            if (near.count == N) CHECK(sum == 0.0);
            else if (model == ShadingModel::isotropic) CHECK(sum == Approx(1.0).epsilon(1e-4));
            else CHECK(sum <= 1.0 + 1e-4);  // the rest: draws that end below the horizon (a zero sample)
        }
    }
}
