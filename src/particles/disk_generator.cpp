#include "accretion/particles/disk_generator.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <tbb/parallel_for.h>

#include "accretion/core/rng.h"
#include "accretion/particles/blackbody.h"

namespace accretion {

double diskTemperature(const ParticleSettings& s, double r) {
    return s.inner_temperature * std::pow(r / s.inner_radius, -s.temperature_exponent);
}

std::pair<double, double> diskTemperatureRange(const ParticleSettings& s) {
    const double inner = diskTemperature(s, s.inner_radius), outer = diskTemperature(s, s.outer_radius);
    return {std::min(inner, outer), std::max(inner, outer)};
}

std::uint8_t temperatureType(const ParticleSettings& s, double kelvin) {
    const auto it = std::upper_bound(s.type_bands.begin(), s.type_bands.end(), kelvin);
    return static_cast<std::uint8_t>(it - s.type_bands.begin());
}

Particles generateDisk(const ParticleSettings& s, std::uint32_t frame, const BlackbodyTable* table) {
    Particles out;
    out.resize(s.count);
    std::optional<BlackbodyTable> own;
    if (!table) {
        const auto [lo, hi] = diskTemperatureRange(s);
        table = &own.emplace(lo, hi);
    }
    const BlackbodyTable& blackbody = *table;
    const double t = double(frame) * s.time_step;
    const double rIn2 = s.inner_radius * s.inner_radius, rOut2 = s.outer_radius * s.outer_radius;

    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, s.count, 4096), [&](const auto& range) {
        for (std::uint32_t k = range.begin(); k != range.end(); ++k) {
            Rng rng(k, 0, RngPass::particles, s.seed);  // frame-independent orbit elements
            const double r = std::sqrt(rIn2 + (rOut2 - rIn2) * rng.uniform());
            const double theta0 = 2.0 * M_PI * rng.uniform();
            // Box-Muller height, flared: sigma(r) = thickness * r / r_out.
            const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
            const double gauss = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
            const double y = gauss * s.thickness * r / s.outer_radius;
            const double size = s.radius * (1.0 + s.radius_jitter * (2.0 * rng.uniform() - 1.0));

            const double omega = std::sqrt(s.gm / (r * r * r));
            const double theta = theta0 + omega * t;
            const double c = std::cos(theta), sn = std::sin(theta);
            out.position[k] = Vec3(float(s.center.x + r * c), float(s.center.y + y), float(s.center.z + r * sn));
            out.velocity[k] = Vec3(float(-omega * r * sn), 0.0f, float(omega * r * c));
            out.radius[k] = float(size);

            const double T = diskTemperature(s, r);
            const double power = s.luminosity * std::pow(T / s.inner_temperature, 4.0);
            out.emission[k] = blackbody(T) * float(power);
            out.type[k] = temperatureType(s, T);
            out.opacity[k] = float(s.opacity);
        }
    });
    return out;
}

}  // namespace accretion
