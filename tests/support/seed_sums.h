#pragma once
// The statistic of the reuse tests (restir, particle_restir): within a
// frame reuse correlates pixels, so each seed's history gives one number,
// the image sum of Lr of its last frame, and the mean over independent
// seeds is compared with the brute-force oracle's image sum.
#include <cstdint>

#include "accretion/render/frame_renderer.h"
#include "accretion/scene/settings.h"

namespace accretion::test {

/// The sum of Lr's three channels over the image.
double imageLrSum(const FrameImage& img);

struct SeedSums {
    double mean = 0.0, stderr = 0.0;
};

/// `estimator` over `seeds` histories (seeds firstSeed, firstSeed + 1, ...)
/// of `frames` frames each: the mean and standard error of the last frame's image sum.
SeedSums seedImageSums(Settings s, EstimatorKind estimator, std::uint32_t frames, std::uint32_t seeds, std::uint64_t firstSeed);

/// The oracle's image sum at `frame` (tests/support/oracle.h): an orbiting
/// camera's pose computed here (the eye rotated about the y axis through
/// look_at), the particles of that frame from the generator.
double oracleImageSum(Settings s, std::uint32_t frame);

}  // namespace accretion::test
