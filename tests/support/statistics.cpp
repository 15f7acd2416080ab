#include "support/statistics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace accretion::test {

double gammaQ(double a, double x) {
    if (x <= 0.0) return 1.0;
    const double lnPrefix = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1.0) {
        // Series for P(a, x).
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 10000; ++n) {
            term *= x / (a + n);
            sum += term;
            if (std::fabs(term) < std::fabs(sum) * 1e-15) break;
        }
        return 1.0 - sum * std::exp(lnPrefix);
    }
    // Lentz continued fraction for Q(a, x).
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        const double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::fabs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::fabs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double delta = d * c;
        h *= delta;
        if (std::fabs(delta - 1.0) < 1e-15) break;
    }
    return std::exp(lnPrefix) * h;
}

double chiSquarePValue(const std::vector<double>& observed, const std::vector<double>& expected) {
    if (observed.size() != expected.size()) throw std::invalid_argument("size mismatch");
    double chi2 = 0.0, pooledObs = 0.0, pooledExp = 0.0;
    int cells = 0;
    for (std::size_t i = 0; i < observed.size(); ++i) {
        if (expected[i] < 5.0) {
            pooledObs += observed[i];
            pooledExp += expected[i];
            continue;
        }
        chi2 += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
        ++cells;
    }
    if (pooledExp > 0.0) {
        chi2 += (pooledObs - pooledExp) * (pooledObs - pooledExp) / pooledExp;
        ++cells;
    } else if (pooledObs > 0.0) {
        return 0.0;  // samples where the pmf is zero
    }
    const int dof = cells - 1;
    if (dof < 1) throw std::invalid_argument("too few cells");
    return gammaQ(0.5 * dof, 0.5 * chi2);
}

double normalTwoSidedP(double z) { return std::erfc(std::fabs(z) / std::sqrt(2.0)); }

namespace {

std::uint32_t seedDivisor() {
    const char* v = std::getenv("ACCRETION_TEST_SEED_DIVISOR");
    if (v == nullptr || *v == '\0') return 1;
    char* end = nullptr;
    const long d = std::strtol(v, &end, 10);
    if (*end != '\0' || d < 1 || d > 1000)
        throw std::invalid_argument(std::string("ACCRETION_TEST_SEED_DIVISOR=") + v + ": expected an integer from 1 to 1000");
    return static_cast<std::uint32_t>(d);
}

}  // namespace

std::uint32_t statisticalSeeds(std::uint32_t full, std::uint32_t minimum) {
    const std::uint32_t d = seedDivisor();
    return d == 1 ? full : std::max(std::min(full, minimum), full / d);
}

bool fullStatisticalPower() { return seedDivisor() == 1; }

}  // namespace accretion::test
