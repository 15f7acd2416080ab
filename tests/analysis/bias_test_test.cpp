// Student's t and the bias test built on it, checked against closed forms
// (t with 1, 2 and 4 degrees of freedom, the normal) and by Monte Carlo:
// with 4 seeds the test's false alarms keep its stated rate, where the
// normal's critical value raises a false alarm about 3 times as often.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include "accretion/analysis/bias_test.h"
#include "accretion/analysis/student_t.h"

using namespace accretion;

namespace {


/// Student's t with 4 degrees of freedom in closed form.
double studentCdfFourDof(double t) {
    const double u = t / std::sqrt(4.0 + t * t);
    return 0.5 + 0.75 * u - 0.25 * u * u * u;
}

/// The fraction of `trials` runs of `seeds` unit-normal seed errors (plus
/// `bias`) that the test calls biased; the reference is exact.
double biasRejectionRate(std::uint32_t seeds, double bias, double zCritical, int trials, std::uint64_t seed, bool normalCritical) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, 1.0);
    int rejected = 0;
    for (int k = 0; k < trials; ++k) {
        double s1 = 0.0, s2 = 0.0;
        for (std::uint32_t s = 0; s < seeds; ++s) {
            const double e = bias + noise(rng);
            s1 += e;
            s2 += e * e;
        }
        const double mean = s1 / seeds;
        const double sd = std::sqrt((s2 - seeds * mean * mean) / (seeds - 1));
        const BiasTest t = biasTest(sd, seeds, 0.0, zCritical);
        if (std::fabs(mean / t.stderr) > (normalCritical ? zCritical : t.critical)) ++rejected;
    }
    return double(rejected) / trials;
}

/// A binomial proportion's half-width at 99.9% (3.29 standard errors).
double rateHalfWidth(double p, int trials) { return 3.29 * std::sqrt(p * (1.0 - p) / trials); }

}  // namespace

TEST_CASE("Student's t quantiles match the closed forms", "[analysis][statistics]") {
    for (const double p : {0.6, 0.8, 0.975, 0.9995, 0.02}) {
        INFO("p = " << p);
        CHECK(studentTQuantile(p, 1.0) == Approx(std::tan(std::numbers::pi * (p - 0.5))).epsilon(1e-10));      // Cauchy
        CHECK(studentTQuantile(p, 2.0) == Approx((2 * p - 1) / std::sqrt(2 * p * (1 - p))).epsilon(1e-10));
        CHECK(studentCdfFourDof(studentTQuantile(p, 4.0)) == Approx(p).epsilon(1e-11));
        CHECK(studentTCdf(studentTQuantile(p, 7.5), 7.5) == Approx(p).epsilon(1e-11));
    }
    // The normal's 99.9% and 95% two-sided values; a large dof tends to them.
    CHECK(studentTQuantile(0.9995, INFINITY) == Approx(3.2905267314919).epsilon(1e-10));
    CHECK(studentTQuantile(0.975, INFINITY) == Approx(1.9599639845401).epsilon(1e-10));
    CHECK(studentTQuantile(0.9995, 1e7) == Approx(3.2905267314919).epsilon(1e-6));
    CHECK_THROWS(studentTQuantile(1.0, 3.0));
    CHECK_THROWS(studentTCdf(1.0, 0.0));
}

TEST_CASE("The bias test's degrees of freedom and critical value", "[analysis][statistics]") {
    // Seeds alone: S - 1 degrees of freedom; 4 seeds at 99.9% need |t| > 12.92.
    const BiasTest four = biasTest(2.0, 4, 0.0, 3.2905267314919);
    CHECK(four.dof == Approx(3.0));
    CHECK(four.stderr == Approx(1.0));
    CHECK(four.critical == Approx(12.924).epsilon(1e-4));
    // Welch-Satterthwaite: a reference noise as large as the seeds' quadruples the dof.
    const BiasTest mixed = biasTest(2.0, 4, 1.0, 3.29);
    CHECK(mixed.dof == Approx(12.0));
    CHECK(mixed.stderr == Approx(std::sqrt(2.0)));
    // Seeds that do not spread: the normal.
    const BiasTest flat = biasTest(0.0, 4, 1.0, 3.2905267314919);
    CHECK(std::isinf(flat.dof));
    CHECK(flat.critical == Approx(3.2905267314919).epsilon(1e-9));
    CHECK(flat.detectable == Approx(3.2905267314919 + 0.8416212335729).epsilon(1e-9));
}

TEST_CASE("seedsToDetect gives the fewest seeds whose bound is under the target", "[analysis][statistics]") {
    const double bound = 1.0;
    const std::uint32_t s = seedsToDetect(3.0, 4, 0.05, 3.29, bound, 1000);
    REQUIRE(s > 4);
    CHECK(biasTest(3.0, s, 0.05, 3.29).detectable <= bound);
    CHECK(biasTest(3.0, s - 1, 0.05, 3.29).detectable > bound);
    CHECK(seedsToDetect(3.0, 4, 0.05, 3.29, bound, s - 1) == 0);
    // A reference noisier than the bound: no number of seeds will do.
    CHECK(seedsToDetect(3.0, 4, 0.5, 3.29, bound, 100000) == 0);
}

TEST_CASE("With 4 seeds the test keeps its false-alarm rate and the normal's value does not", "[analysis][statistics]") {
    // 95% two-sided, 40000 unbiased runs of 4 seeds: the t test rejects 5%;
    // the normal's 1.96 rejects P(|t_3| > 1.96) = 14.5%. Both at 99.9% confidence.
    constexpr int kTrials = 40000;
    const double t = biasRejectionRate(4, 0.0, 1.9599639845401, kTrials, 1, false);
    const double z = biasRejectionRate(4, 0.0, 1.9599639845401, kTrials, 1, true);
    CHECK(std::fabs(t - 0.05) < rateHalfWidth(0.05, kTrials));
    const double normalRate = 2.0 * (1.0 - studentTCdf(1.9599639845401, 3.0));
    CHECK(normalRate == Approx(0.145).margin(0.001));
    CHECK(std::fabs(z - normalRate) < rateHalfWidth(normalRate, kTrials));
}

TEST_CASE("A bias of the detectable size is found about 4 times in 5", "[analysis][statistics]") {
    // The bound is (t_crit + t_0.8) standard errors, the usual approximation
    // of the noncentral t; with 8 seeds and a 99% test its power is near 80%.
    constexpr int kTrials = 20000;
    constexpr std::uint32_t kSeeds = 8;
    const BiasTest atSigma = biasTest(1.0, kSeeds, 0.0, 2.5758293035489);
    const double power = biasRejectionRate(kSeeds, atSigma.detectable, 2.5758293035489, kTrials, 2, false);
    INFO("power " << power);
    CHECK(power > 0.75);
    CHECK(power < 0.85);
}
