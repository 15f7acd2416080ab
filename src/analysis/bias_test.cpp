#include "accretion/analysis/bias_test.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "accretion/analysis/student_t.h"

namespace accretion {

BiasTest biasTest(double seedSd, std::uint32_t seeds, double referenceStderr, double zCritical) {
    if (seeds < 2) throw std::invalid_argument("biasTest: at least 2 seeds are needed for a standard deviation");
    const double seedVar = seedSd * seedSd / seeds;
    const double refVar = referenceStderr * referenceStderr;
    BiasTest t;
    t.stderr = std::sqrt(seedVar + refVar);
    t.dof = seedVar > 0.0 ? (seedVar + refVar) * (seedVar + refVar) / (seedVar * seedVar / double(seeds - 1))
                          : std::numeric_limits<double>::infinity();
    const double alpha = 2.0 * (1.0 - normalCdf(zCritical));  // two-sided
    constexpr double kPower = 0.8;
    t.critical = studentTQuantile(1.0 - 0.5 * alpha, t.dof);
    t.detectable = (t.critical + studentTQuantile(kPower, t.dof)) * t.stderr;
    return t;
}

std::uint32_t seedsToDetect(double seedSd, std::uint32_t seeds, double referenceStderr, double zCritical, double bound,
                            std::uint32_t maxSeeds) {
    for (std::uint32_t s = std::max<std::uint32_t>(seeds + 1, 2); s <= maxSeeds; ++s)
        if (biasTest(seedSd, s, referenceStderr, zCritical).detectable <= bound) return s;
    return 0;
}

}  // namespace accretion
