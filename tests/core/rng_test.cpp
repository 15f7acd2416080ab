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
