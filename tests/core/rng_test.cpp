#include <catch2/catch.hpp>

#include <set>

#include "accretion/core/rng.h"
#include "support/statistics.h"

using namespace accretion;

TEST_CASE("per-pixel streams are reproducible and distinct", "[rng]") {
    Rng a(5, 2, RngPass::lightSampling, 9), b(5, 2, RngPass::lightSampling, 9);
    for (int i = 0; i < 100; ++i) REQUIRE(a.next() == b.next());
    std::set<std::uint32_t> firsts;
    for (std::uint64_t px = 0; px < 1000; ++px) firsts.insert(Rng(px, 0, RngPass::lightSampling, 9).next());
    for (std::uint32_t f = 0; f < 100; ++f) firsts.insert(Rng(0, f + 1, RngPass::lightSampling, 9).next());
    firsts.insert(Rng(0, 0, RngPass::particles, 9).next());
    REQUIRE(firsts.size() >= 1099);  // 32-bit outputs: a collision or two is possible, not more
}

TEST_CASE("uniform() is uniform on the unit interval (chi-square, 64 bins)", "[rng][statistical]") {
    Rng rng(1, 0, RngPass::lightSampling, 3);
    std::vector<double> observed(64, 0.0), expected(64, 1e6 / 64);
    for (int i = 0; i < 1'000'000; ++i) {
        const float u = rng.uniform();
        REQUIRE((u >= 0.0f && u < 1.0f));
        ++observed[std::size_t(u * 64)];
    }
    CHECK(accretion::test::chiSquarePValue(observed, expected) > 1e-4);
}

TEST_CASE("uniformInt(IntBound) draws the numbers of pcg's bounded_rand", "[rng]") {
    // The remainder by multiplication against %, on the bounds and draws
    // where it could go wrong (1, powers of two and their neighbours, the
    // largest bounds and draws) and on random ones.
    std::vector<std::uint32_t> bounds = {1, 2, 3, 5, 7, 1000, 100'000, 999'983, 0x7fffffffu, 0x80000000u, 0x80000001u,
                                         0xfffffffeu, 0xffffffffu};
    for (int k = 2; k < 32; ++k) bounds.insert(bounds.end(), {(1u << k) - 1, 1u << k, (1u << k) + 1});
    Rng pick(7, 0, RngPass::particles, 1);
    for (int k = 0; k < 2000; ++k) bounds.push_back(std::max(1u, pick.next() >> (pick.next() % 32)));
    for (const std::uint32_t n : bounds) {
        const IntBound b(n);
        REQUIRE(b.threshold == (0u - n) % n);
        for (const std::uint32_t r : {0u, 1u, n - 1, n, n + 1, 0xffffffffu, 0xfffffffeu, 0x80000000u})
            REQUIRE(b.mod(r) == r % n);
        for (int i = 0; i < 200; ++i) {
            const std::uint32_t r = pick.next();
            REQUIRE(b.mod(r) == r % n);
        }
        Rng x(n, 1, RngPass::lightSampling, 2), y(n, 1, RngPass::lightSampling, 2);
        for (int i = 0; i < 20; ++i) REQUIRE(x.uniformInt(b) == y.uniformInt(n));
    }
}

TEST_CASE("PortableRng (the GPU twin's stream) draws Rng's numbers", "[rng]") {
    // Streams of many items, frames, passes and seeds, sub-streams included;
    // raw words, uniforms and bounded integers (bounds with large rejection
    // thresholds too) in one interleaved sequence each.
    const std::uint32_t bounds[] = {1, 2, 3, 7, 100, 10000, 100003, 0x80000001u, 0xfffffffbu};
    std::size_t draws = 0;
    for (std::uint64_t item : {0ull, 1ull, 57599ull, 1ull << 40, ~0ull})
        for (std::uint32_t frame : {0u, 3u, 0xffffffffu})
            for (RngPass pass : {RngPass::lightSampling, RngPass::restirCandidates, RngPass::restirSpatial})
                for (std::uint64_t seed : {0ull, 12345ull})
                    for (std::uint64_t sub : {0ull, 9ull}) {
                        Rng a(item, frame, pass, seed, sub);
                        PortableRng b(item, frame, pass, seed, sub);
                        for (int k = 0; k < 40; ++k, draws += 3) {
                            REQUIRE(a.next() == b.next());
                            REQUIRE(a.uniform() == b.uniform());
                            const std::uint32_t n = bounds[k % 9];
                            REQUIRE(a.uniformInt(n) == b.uniformInt(n));
                        }
                    }
    CHECK(draws == 5 * 3 * 3 * 2 * 2 * 40 * 3);
}
