#pragma once
#include <cstdint>

#include "accretion/particles/blackbody.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Temperature of the disk at radius r: T_in (r / r_in)^(-exponent).
double diskTemperature(const ParticleSettings& s, double r);

/// Particle type = index of the temperature band (type_bands thresholds).
std::uint8_t temperatureType(const ParticleSettings& s, double kelvin);

/// The accretion disk at a frame (docs/MODEL.md section 1): area-uniform radii in
/// [r_in, r_out], flared Gaussian height, Keplerian orbits (angular speed
/// sqrt(GM / r^3)), blackbody emission of T(r) with luminance
/// luminosity * (T / T_in)^4. Particle k depends only on (seed, k, frame).
/// `table` (optional) saves building the blackbody table on every call.
Particles generateDisk(const ParticleSettings& s, std::uint32_t frame, const BlackbodyTable* table = nullptr);

}  // namespace accretion
