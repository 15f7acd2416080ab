#pragma once
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// Linear Rec.709 colour of a blackbody at temperature T (kelvin), scaled to
/// luminance 1, negative components clipped. Planck's law integrated against
/// the CIE 1931 observer (multi-lobe Gaussian fit of Wyman et al. 2013).
Vec3 blackbodyColor(double kelvin);

/// blackbodyColor tabulated on a log-spaced temperature grid (2048 entries
/// from 500 K to 1e6 K), read by linear interpolation, for generators.
/// Each entry integrates Planck's law over 471 wavelengths: the whole table
/// cost every process that generated a disk about 60 ms of CPU, where a
/// disk's temperatures read a few per cent of it.
class BlackbodyTable {
public:
    /// Every entry.
    BlackbodyTable();
    /// The entries that temperatures in [loKelvin, hiKelvin] read (a disk's
    /// range, diskTemperatureRange); a temperature outside it reads its two
    /// entries computed when asked. Every read gives the whole table's value,
    /// bit for bit.
    BlackbodyTable(double loKelvin, double hiKelvin);
    Vec3 operator()(double kelvin) const;

private:
    Vec3 entry(std::size_t i) const;

    std::vector<DVec3> cie_;  ///< the observer at 1 nm, 360..830 nm
    std::size_t first_ = 0;   ///< table_[0] is entry first_ of the grid
    std::vector<Vec3> table_;
};

}  // namespace accretion
