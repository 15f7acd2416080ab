#pragma once
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// relMSE over S seeds of one estimator, split per pixel into what the
/// seeds share and what they do not (docs/MODEL.md section 5's relMSE, its
/// weights 1 / (ref^2 + eps)). With m the pixel's mean error over the seeds
/// and v its unbiased variance:
///   noise      = mean of v / (ref^2 + eps): what more seeds, rays or frames
///                of history average away;
///   persistent = mean of (m^2 - v / S) / (ref^2 + eps), less the
///                reference's own noise: the per-pixel bias (interpolation,
///                a history's lag), which they do not.
/// persistent + noise is the mean over the seeds of one render's relMSE
/// less the reference's noise (bias's rel_mse), exactly; persistent is
/// unbiased, so it can come out a little below 0 where there is none.
struct ErrorAnatomy {
    double persistent = 0.0;
    double noise = 0.0;
};

/// `sum` and `sumSq`: per pixel, the seeds' errors x - ref summed and
/// squared-summed; `seeds` >= 2; `refStderr` (or empty) the reference's
/// per-pixel standard error.
ErrorAnatomy splitRelMse(const std::vector<DVec3>& sum, const std::vector<DVec3>& sumSq, double seeds,
                         const std::vector<Vec3>& ref, const std::vector<Vec3>& refStderr, double eps);

/// The same split over groups of pixels (group[p] < groups; each group's
/// parts are its pixels' share of the whole image's, so that the groups'
/// parts sum to splitRelMse's).
std::vector<ErrorAnatomy> splitRelMseByGroup(const std::vector<DVec3>& sum, const std::vector<DVec3>& sumSq, double seeds,
                                             const std::vector<Vec3>& ref, const std::vector<Vec3>& refStderr, double eps,
                                             const std::vector<std::uint32_t>& group, std::uint32_t groups);

/// A visible particle's light summed over the pixels that see it, and how many.
struct ParticlePixels {
    DVec3 sum{0.0};
    std::size_t pixels = 0;
    DVec3 mean() const { return sum / double(pixels); }
};
/// Each particle's ParticlePixels in an image (ids: its particle.id;
/// kNoParticle pixels left out).
std::unordered_map<std::uint32_t, ParticlePixels> particlePixels(const std::vector<Vec3>& light, const std::vector<std::uint32_t>& ids);

/// The floor of shading one value per visible particle: the relMSE of the
/// image whose every pixel holds its particle's mean reference light over
/// the pixels measured (ids: the reference's particle.id, kNoParticle
/// pixels kept as they are), less the reference's own noise. No design
/// whose pixels read one texel a particle errs less, however long its
/// history; a particle cut by a crop's edge is averaged over its part in
/// the crop, so the floor over crops is a lower bound.
struct ParticleMeanFloor {
    double relMSE = 0.0;
    std::size_t particles = 0;   ///< distinct visible particles
    double medianPixels = 0.0;   ///< pixels a visible particle covers, its median
};
ParticleMeanFloor particleMeanFloor(const std::vector<Vec3>& ref, const std::vector<std::uint32_t>& ids,
                                    const std::vector<Vec3>& refStderr, double eps);

}  // namespace accretion
