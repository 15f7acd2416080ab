#pragma once
#include <cstdint>

namespace accretion {

/// The test of a mean signed error for bias: `seeds` independent renders
/// whose image-mean signed errors have sample standard deviation `seedSd`
/// (S - 1 degrees of freedom), against a reference whose own image mean has
/// standard error `referenceStderr` (estimated from far more samples: known).
/// The statistic mean / stderr is Student's t with Welch-Satterthwaite's
/// degrees of freedom; with few seeds its critical value is far above the
/// normal's (4 seeds at 99.9%: 12.9, not 3.29).
struct BiasTest {
    double stderr = 0.0;       ///< of the mean signed error: sqrt(seedSd^2 / S + referenceStderr^2)
    double dof = 0.0;          ///< Welch-Satterthwaite's (infinite where the seeds do not spread)
    double critical = 0.0;     ///< the two-sided critical |t| at the significance of the normal's zCritical
    double detectable = 0.0;   ///< the smallest |bias| found with 80% probability: (critical + t_0.8) stderrs
};

/// `zCritical` names the significance as the normal's two-sided critical
/// value (3.29: 99.9%); the test keeps that significance at any dof.
BiasTest biasTest(double seedSd, std::uint32_t seeds, double referenceStderr, double zCritical);

/// The fewest seeds, above `seeds` and at most `maxSeeds`, whose detectable
/// bias is at most `bound` (in the units of seedSd), were the seeds to
/// spread as these did; 0 when none is.
std::uint32_t seedsToDetect(double seedSd, std::uint32_t seeds, double referenceStderr, double zCritical, double bound,
                            std::uint32_t maxSeeds);

}  // namespace accretion
