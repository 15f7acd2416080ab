#pragma once
#include <cstdint>
#include <vector>

namespace accretion::test {

/// Regularised upper incomplete gamma Q(a, x) (series / continued fraction).
double gammaQ(double a, double x);

/// Pearson chi-square test of observed counts against expected counts; cells
/// with expected < 5 are pooled. Returns the p-value.
double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& expected);

/// Two-sided normal p-value of a z-score.
double normalTwoSidedP(double z);

/// The seeds a statistical test over seeds runs: `full`, or full divided by
/// the environment's ACCRETION_TEST_SEED_DIVISOR (at least `minimum`). The
/// sanitizer stage (scripts/sanitize.sh) sets it to 8: there the tests run
/// every code path under AddressSanitizer and UBSan at the same confidence
/// (the same |z| bound) but with less power; the Release stage runs them
/// whole. A divisor that is not a positive integer fails the test.
std::uint32_t statisticalSeeds(std::uint32_t full, std::uint32_t minimum = 8);
/// Whether statisticalSeeds gives every seed (no divisor): a test's check of
/// its own power (that it would see a 5% bias) holds only then.
bool fullStatisticalPower();

}  // namespace accretion::test
