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

}  // namespace accretion::test
