#pragma once

namespace accretion {

/// The standard normal's cumulative distribution at x.
double normalCdf(double x);

/// Student's t distribution with `dof` degrees of freedom (any real dof > 0;
/// an infinite dof is the standard normal): its cumulative distribution at t.
double studentTCdf(double t, double dof);

/// The p-quantile (0 < p < 1) of Student's t with `dof` degrees of freedom:
/// the t with studentTCdf(t, dof) = p, to about 1e-12 relative.
double studentTQuantile(double p, double dof);

}  // namespace accretion
