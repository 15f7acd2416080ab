#include "accretion/analysis/student_t.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace accretion {
namespace {

/// The continued fraction of the regularised incomplete beta function,
/// evaluated by the modified Lentz method; converges fast for x < (a + 1) / (a + b + 2).
double betaContinuedFraction(double a, double b, double x) {
    constexpr double kTiny = 1e-300;
    constexpr double kEps = 1e-15;
    double c = 1.0;
    double d = 1.0 - (a + b) * x / (a + 1.0);
    d = 1.0 / (std::fabs(d) < kTiny ? kTiny : d);
    double f = d;
    for (int m = 1; m <= 10000; ++m) {
        const double m2 = 2.0 * m;
        // The even step, then the odd one.
        for (const double coefficient : {m * (b - m) * x / ((a + m2 - 1.0) * (a + m2)),
                                         -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0))}) {
            d = 1.0 + coefficient * d;
            d = 1.0 / (std::fabs(d) < kTiny ? kTiny : d);
            c = 1.0 + coefficient / c;
            if (std::fabs(c) < kTiny) c = kTiny;
            const double delta = c * d;
            f *= delta;
            if (coefficient < 0.0 && std::fabs(delta - 1.0) < kEps) return f;
        }
    }
    return f;
}

/// The regularised incomplete beta function I_x(a, b), 0 <= x <= 1.
double incompleteBeta(double a, double b, double x) {
    if (x <= 0.0) return 0.0;
    if (x >= 1.0) return 1.0;
    const double logFront = std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x);
    const double front = std::exp(logFront);
    if (x < (a + 1.0) / (a + b + 2.0)) return front * betaContinuedFraction(a, b, x) / a;
    return 1.0 - front * betaContinuedFraction(b, a, 1.0 - x) / b;
}

}  // namespace

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

double studentTCdf(double t, double dof) {
    if (!(dof > 0.0)) throw std::invalid_argument("studentTCdf: degrees of freedom must be positive");
    if (std::isinf(dof)) return normalCdf(t);
    // P(|T| > |t|) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2).
    const double tail = 0.5 * incompleteBeta(0.5 * dof, 0.5, dof / (dof + t * t));
    return t >= 0.0 ? 1.0 - tail : tail;
}

double studentTQuantile(double p, double dof) {
    if (!(p > 0.0 && p < 1.0)) throw std::invalid_argument("studentTQuantile: p must be in (0, 1)");
    if (p == 0.5) return 0.0;
    if (p < 0.5) return -studentTQuantile(1.0 - p, dof);
    // Bracket, then bisect: the cdf is increasing; 200 halvings exhaust a double.
    double lo = 0.0, hi = 1.0;
    while (studentTCdf(hi, dof) < p) {
        lo = hi;
        hi *= 2.0;
        if (hi > 1e300) return std::numeric_limits<double>::infinity();
    }
    for (int k = 0; k < 200 && hi - lo > 1e-13 * hi; ++k) {
        const double mid = 0.5 * (lo + hi);
        (studentTCdf(mid, dof) < p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace accretion
