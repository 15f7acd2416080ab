#include "accretion/particles/blackbody.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <tbb/parallel_for.h>

namespace accretion {
namespace {

// Piecewise Gaussian lobe of the CIE fit.
double lobe(double x, double mu, double s1, double s2) {
    const double t = (x - mu) / (x < mu ? s1 : s2);
    return std::exp(-0.5 * t * t);
}

DVec3 cieXYZ(double nm) {
    return {1.056 * lobe(nm, 599.8, 37.9, 31.0) + 0.362 * lobe(nm, 442.0, 16.0, 26.7) - 0.065 * lobe(nm, 501.1, 20.4, 26.2),
            0.821 * lobe(nm, 568.8, 46.9, 40.5) + 0.286 * lobe(nm, 530.9, 16.3, 31.1),
            1.217 * lobe(nm, 437.0, 11.8, 36.0) + 0.681 * lobe(nm, 459.0, 26.0, 13.8)};
}

// Relative spectral radiance (Planck), wavelength in nm.
double planck(double nm, double kelvin) {
    constexpr double c2 = 1.4387769e7;  // second radiation constant, nm K
    return std::pow(nm, -5.0) / std::expm1(c2 / (nm * kelvin));
}

}  // namespace

namespace {

/// Linear Rec.709 of the blackbody, normalised to luminance 1, from a
/// tabulated 1 nm CIE sampling (cie[k] at 360 + k nm).
Vec3 blackbodyFromCie(double kelvin, const std::vector<DVec3>& cie) {
    DVec3 xyz(0.0);
    for (std::size_t k = 0; k < cie.size(); ++k) xyz += planck(360.0 + double(k), kelvin) * cie[k];
    // XYZ -> linear Rec.709 (D65).
    DVec3 rgb(3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
              -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
              0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z);
    rgb = glm::max(rgb, DVec3(0.0));
    const double y = 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
    return y > 0.0 ? Vec3(rgb / y) : Vec3(0.0f);
}

std::vector<DVec3> cieTable() {
    std::vector<DVec3> cie;
    for (int nm = 360; nm <= 830; ++nm) cie.push_back(cieXYZ(double(nm)));
    return cie;
}

}  // namespace

Vec3 blackbodyColor(double kelvin) { return blackbodyFromCie(kelvin, cieTable()); }

namespace {

constexpr int kEntries = 2048;
const double kLogMin = std::log(500.0), kLogMax = std::log(1e6);

/// The grid's position of a temperature: entry index plus fraction, clamped to the grid.
double gridPosition(double kelvin) {
    const double u = (std::log(kelvin) - kLogMin) / (kLogMax - kLogMin) * double(kEntries - 1);
    return std::clamp(u, 0.0, double(kEntries - 1));
}

/// The temperature of entry i of the grid.
double gridKelvin(std::size_t i) { return std::exp(kLogMin + (kLogMax - kLogMin) * double(i) / (kEntries - 1)); }

}  // namespace

BlackbodyTable::BlackbodyTable() : BlackbodyTable(0.0, std::numeric_limits<double>::infinity()) {}

BlackbodyTable::BlackbodyTable(double loKelvin, double hiKelvin) : cie_(cieTable()) {
    const double lo = loKelvin > 0.0 ? gridPosition(loKelvin) : 0.0, hi = gridPosition(hiKelvin);
    first_ = std::min(static_cast<std::size_t>(lo), std::size_t(kEntries - 2));
    const std::size_t last = std::min(static_cast<std::size_t>(hi) + 1, std::size_t(kEntries - 1));
    table_.resize(last + 1 - first_);
    tbb::parallel_for(std::size_t(0), table_.size(), [&](std::size_t i) {
        table_[i] = blackbodyFromCie(gridKelvin(first_ + i), cie_);
    });
}

Vec3 BlackbodyTable::entry(std::size_t i) const {
    return i >= first_ && i - first_ < table_.size()
               ? table_[i - first_]
               : blackbodyFromCie(gridKelvin(i), cie_);
}

Vec3 BlackbodyTable::operator()(double kelvin) const {
    const double c = gridPosition(kelvin);
    const std::size_t i = std::min(static_cast<std::size_t>(c), std::size_t(kEntries - 2));
    const float f = static_cast<float>(c - double(i));
    return entry(i) * (1.0f - f) + entry(i + 1) * f;
}

}  // namespace accretion
