// Opacity micromap classification of the disc against dense point sampling
// of every micro-triangle, at every level.
#include <catch2/catch.hpp>

#include <set>

#include "accretion/geometry/billboard.h"
#include "accretion/geometry/opacity_micromap.h"

using namespace accretion;

TEST_CASE("micro-triangle indexing covers the triangle once and round-trips", "[gpu][omm]") {
    for (std::uint32_t L = 0; L <= 6; ++L) {
        const std::uint32_t m = 1u << (2 * L);
        double area = 0.0;
        for (std::uint32_t k = 0; k < m; ++k) {
            const auto c = OpacityMicromap::microCorners(L, k);
            const Vec2 centroid = (c[0] + c[1] + c[2]) / 3.0f;
            REQUIRE(OpacityMicromap::microIndex(L, centroid.x, centroid.y) == k);
            area += 0.5 * std::abs(double(c[1].x - c[0].x) * (c[2].y - c[0].y) - double(c[2].x - c[0].x) * (c[1].y - c[0].y));
        }
        CHECK(area == Approx(0.5).epsilon(1e-9));
    }
}

TEST_CASE("OMM classification of the disc matches dense point sampling at every level", "[gpu][omm]") {
    for (std::uint32_t L = 0; L <= 6; ++L) {
        const OpacityMicromap omm(L, true);
        std::uint64_t unknown = 0;
        for (std::uint32_t tri = 0; tri < 2; ++tri)
            for (std::uint32_t k = 0; k < omm.microTriangles(); ++k) {
                const auto b = OpacityMicromap::microCorners(L, k);
                // 32 x 32 barycentric samples, corners and edges included.
                constexpr int S = 32;
                int inside = 0, total = 0;
                float nearest = 1.0f;  // closest approach of a sample to the circle
                for (int a = 0; a <= S; ++a)
                    for (int c = 0; c <= S - a; ++c) {
                        const Vec2 bary = b[0] + (float(a) / S) * (b[1] - b[0]) + (float(c) / S) * (b[2] - b[0]);
                        const Vec2 uv = OpacityMicromap::quadUvOf(tri, bary);
                        inside += insideDisc(uv);
                        nearest = std::min(nearest, std::abs(glm::length(uv - Vec2(0.5f)) - 0.5f));
                        ++total;
                    }
                const OmmState s = omm.state(tri, k);
                INFO("level " << L << " triangle " << tri << " micro " << k);
                if (s == OmmState::opaque) REQUIRE(inside == total);
                if (s == OmmState::transparent) REQUIRE(inside == 0);
                if (s == OmmState::unknown) {
                    ++unknown;
                    // Crossed by the circle: both sides are sampled, or the
                    // circle only grazes it, within one sample spacing.
                    const bool both = inside > 0 && inside < total;
                    if (!both) CHECK(nearest < 1.5f * 1.4143f / float(1u << L) / S);
                }
            }
        // The unknown micro-triangles hug the circle: their number grows like 2^L, their area falls like 2^-L.
        if (L >= 2) CHECK(double(unknown) / omm.microTriangles() < 8.0 / double(1u << L));
        CHECK(omm.count(OmmState::opaque) + omm.count(OmmState::transparent) + omm.count(OmmState::unknown) ==
              2u * omm.microTriangles());
    }
}

TEST_CASE("2-state OMM has no unknown micro-triangles, memory is shared across billboards", "[gpu][omm]") {
    const OpacityMicromap two(4, false), four(4, true);
    CHECK(two.count(OmmState::unknown) == 0);
    CHECK(four.count(OmmState::unknown) > 0);
    CHECK(four.arrayBytes() == 256u * 2u / 8u);
    CHECK(two.arrayBytes() == 256u / 8u);
    const OmmMemory m = ommMemory(four, 1000);
    CHECK(m.sharedBytes == 2u * 64u + 2u * 2000u);
    CHECK(m.perTriangleBytes == 2000u * 64u + 4u * 2000u);
}

#include "accretion/geometry/particle_bvh.h"
#include "accretion/particles/disk_generator.h"
#include "accretion/geometry/camera.h"
#include "support/test_scenes.h"

TEST_CASE("4-state OMM keeps every hit of alpha testing with fewer any-hits as L grows, 2-state none", "[gpu][omm][bvh]") {
    GeometrySettings g;
    g.alpha = AlphaMode::disc;
    g.cluster_size = 32;
    const auto [ps, cs] = accretion::test::smallView(2000, 3.0, 0.08, Vec3(0.0f, 2.0f, 6.0f), 96, 64);
    const Particles p = generateDisk(ps, 0);
    const Camera cam = Camera::atFrame(cs, 0);
    EmbreeDevice device;

    auto trace = [&](const GpuSettings& gpu, std::vector<std::uint32_t>& ids) {
        ParticleBvh bvh(device, g, gpu);
        bvh.build(p, cam);
        std::uint64_t anyHits = 0;
        ids.clear();
        for (std::uint32_t y = 0; y < cam.height; ++y)
            for (std::uint32_t x = 0; x < cam.width; ++x) {
                SurfaceHit hit;
                RayCounters rc;
                ids.push_back(bvh.intersect(cam.position, cam.pixelDirection(x, y), 1e30f, hit, &rc) ? hit.particle : ~0u);
                anyHits += rc.anyHits;
            }
        return anyHits;
    };
    GpuSettings gpu;
    gpu.counters = true;
    std::vector<std::uint32_t> reference, ids;
    const std::uint64_t alphaAnyHits = trace(gpu, reference);
    REQUIRE(alphaAnyHits > 1000);
    std::uint64_t previous = alphaAnyHits;
    gpu.omm = OmmMode::four_state;
    for (std::uint32_t L = 0; L <= 6; ++L) {
        gpu.omm_level = L;
        const std::uint64_t n = trace(gpu, ids);
        INFO("level " << L << ": " << n << " any-hits (alpha " << alphaAnyHits << ")");
        CHECK(ids == reference);  // the same image as alpha testing
        CHECK(n <= previous);
        previous = n;
    }
    CHECK(previous * 5 < alphaAnyHits);  // level 6 leaves a thin band of unknown micro-triangles
    gpu.omm = OmmMode::two_state;
    gpu.omm_level = 2;
    CHECK(trace(gpu, ids) == 0);
    CHECK(ids != reference);  // 2-state changes coverage at level 2
}
