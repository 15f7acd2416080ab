#include <catch2/catch.hpp>

#include "accretion/core/rng.h"
#include "accretion/lighting/alias_table.h"
#include "support/statistics.h"

using namespace accretion;

TEST_CASE("alias table sampling frequencies match the pmf (chi-square)", "[alias][statistical]") {
    // Skewed weights with zeros and a dominant entry.
    std::vector<float> w = {0.0f, 1.0f, 2.0f, 0.5f, 10.0f, 0.0f, 3.0f, 0.25f, 7.0f, 1e-3f, 4.0f, 0.75f};
    for (int i = 0; i < 100; ++i) w.push_back(float(1 + (i * 37) % 11));
    const AliasTable table(w);
    double total = 0.0;
    for (float x : w) total += x;
    for (std::uint32_t i = 0; i < w.size(); ++i) REQUIRE(table.pmf(i) == Approx(w[i] / total).epsilon(1e-6));

    const int n = 2'000'000;
    std::vector<double> observed(w.size(), 0.0), expected(w.size());
    Rng rng(0, 0, RngPass::lightSampling, 1234);
    for (int k = 0; k < n; ++k) {
        const std::uint32_t bucket = rng.uniformInt(table.size());
        ++observed[table.sample(bucket, rng.uniform())];
    }
    for (std::size_t i = 0; i < w.size(); ++i) expected[i] = n * w[i] / total;
    REQUIRE(observed[0] == 0.0);
    REQUIRE(observed[5] == 0.0);
    // Confidence 1e-4: a correct table fails this once in 10^4 seeds (fixed seed here).
    CHECK(accretion::test::chiSquarePValue(observed, expected) > 1e-4);

    SECTION("the harness rejects a wrong pmf") {
        std::vector<double> skewed = expected;
        skewed[4] *= 1.05;  // ~9 sigma on this cell
        skewed[8] *= 0.95;
        CHECK(accretion::test::chiSquarePValue(observed, skewed) < 1e-4);
    }
}

TEST_CASE("chi-square harness: gammaQ closed forms", "[statistics]") {
    // Q(1, x) = exp(-x); Q(1/2, x) = erfc(sqrt(x)).
    for (double x : {0.1, 1.0, 3.0, 10.0}) {
        REQUIRE(accretion::test::gammaQ(1.0, x) == Approx(std::exp(-x)).epsilon(1e-10));
        REQUIRE(accretion::test::gammaQ(0.5, x) == Approx(std::erfc(std::sqrt(x))).epsilon(1e-8));
    }
}
