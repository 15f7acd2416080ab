#pragma once
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// Linear Rec.709 colour of a blackbody at temperature T (kelvin), scaled to
/// luminance 1, negative components clipped. Planck's law integrated against
/// the CIE 1931 observer (multi-lobe Gaussian fit of Wyman et al. 2013).
Vec3 blackbodyColor(double kelvin);

/// blackbodyColor tabulated on a log-spaced temperature grid, for generators.
class BlackbodyTable {
public:
    BlackbodyTable(double minKelvin = 500.0, double maxKelvin = 1e6, int entries = 2048);
    Vec3 operator()(double kelvin) const;

private:
    double logMin_, logMax_;
    std::vector<Vec3> table_;
};

}  // namespace accretion
