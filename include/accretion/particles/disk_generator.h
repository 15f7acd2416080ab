#pragma once
#include <cstdint>
#include <utility>

#include "accretion/particles/blackbody.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Temperature of the disk at radius r: T_in (r / r_in)^(-exponent).
double diskTemperature(const ParticleSettings& s, double r);

/// The disk's temperatures: T at r_in and at r_out, the lower first.
std::pair<double, double> diskTemperatureRange(const ParticleSettings& s);

/// Particle type = index of the temperature band (type_bands thresholds).
std::uint8_t temperatureType(const ParticleSettings& s, double kelvin);

/// The accretion disk at a frame (docs/MODEL.md section 1): area-uniform radii in
/// [r_in, r_out], flared Gaussian height, Keplerian orbits (angular speed
/// sqrt(GM / r^3)), blackbody emission of T(r) with luminance
/// luminosity * (T / T_in)^4. Particle k depends only on (seed, k, frame).
/// `table` (optional, one covering diskTemperatureRange) saves building the
/// blackbody table's entries on every call.
Particles generateDisk(const ParticleSettings& s, std::uint32_t frame, const BlackbodyTable* table = nullptr);

}  // namespace accretion
