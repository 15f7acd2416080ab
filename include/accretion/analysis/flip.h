#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/colour.h"
#include "accretion/core/math.h"

namespace accretion {

/// FLIP (Andersson et al., "FLIP: A Difference Evaluator for Alternating
/// Images", HPG 2020) and HDR-FLIP (Andersson et al., "Visualizing Errors in
/// Rendered High Dynamic Range Images", Eurographics 2021): a per-pixel
/// perceptual difference in [0, 1] for an observer at `ppd` pixels per
/// degree (default: a 0.7 m wide 4K monitor seen from 0.7 m).
struct FlipOptions {
    double ppd = 0.7 * 3840.0 / 0.7 * 3.14159265358979323846 / 180.0;  ///< pixels per degree of visual angle
};

/// LDR-FLIP of two sRGB-encoded images with values in [0, 1] (w x h, row
/// by row): colour (CSF-filtered YyCxCz, Hunt-adjusted L*a*b*, HyAB) and
/// features (edges and points of the achromatic channel), combined as
/// deltaE_c ^ (1 - deltaE_f).
std::vector<float> ldrFlip(const std::vector<Vec3>& reference, const std::vector<Vec3>& test, std::uint32_t w,
                           std::uint32_t h, const FlipOptions& options = {});

/// HDR-FLIP of two linear-radiance images: the per-pixel maximum of
/// LDR-FLIP over exposures from `start` to `stop` (one stop apart or
/// closer), each image exposed, tone-mapped by the ACES fit (Narkowicz) and
/// sRGB-encoded. Start and stop come from the reference: its largest
/// luminance maps to 0.85 after tone mapping at the start exposure, its
/// median luminance at the stop exposure.
struct HdrFlip {
    std::vector<float> error;  ///< per pixel, in [0, 1]
    double startExposure = 0.0, stopExposure = 0.0;
    int exposures = 0;
};
HdrFlip hdrFlip(const std::vector<Vec3>& reference, const std::vector<Vec3>& test, std::uint32_t w, std::uint32_t h,
                const FlipOptions& options = {});

/// The exposure range HDR-FLIP derives from a reference (start, stop).
std::pair<double, double> flipExposureRange(const std::vector<Vec3>& reference);


}  // namespace accretion
