#pragma once
// A pixel's Monte Carlo sums (docs/MODEL.md section 4) and the rules that
// turn them into Lr, its standard error and adaptive sampling's stop: shared
// by the CPU's uniform / power / tree / ris chunks and the OptiX twin's
// sampling raygen, so that both resolve the same sums to the same floats.
#include <cstdint>

#include "accretion/core/math.h"

namespace accretion {

/// One test for three components: a NaN or Inf component makes the sum
/// non-finite, and float-derived doubles cannot overflow a double sum.
ACC_HD inline bool finiteSum(const DVec3& v) { return isFiniteNumber(v.x + v.y + v.z); }

/// Running sums of one pixel's samples, with the non-finite policy
/// (render.nonfinite) applied to every sample added.
struct SampleSums {
    DVec3 sum{0.0}, sumSq{0.0};
    std::uint32_t n = 0;
    std::uint32_t rejected = 0;
    bool discardNonFinite = false;  ///< render.nonfinite = discard (else zero_sample)

    /// Count a non-finite value; true if the policy discards it (else it counts as 0).
    ACC_HD bool reject() {
        ++rejected;
        return discardNonFinite;
    }
    ACC_HD void add(const DVec3& x) {
        if (!finiteSum(x)) {
            if (!reject()) ++n;
            return;
        }
        sum += x;
        sumSq += x * x;
        ++n;
    }
    ACC_HD void addZero() { ++n; }
};

/// Mean and standard error of the mean of n samples with these sums (n > 0).
ACC_HD inline void meanAndError(const DVec3& sum, const DVec3& sumSq, std::uint32_t n, DVec3& mean, DVec3& err) {
    mean = sum / double(n);
    const DVec3 var = n > 1 ? glm::max((sumSq - double(n) * mean * mean) / double(n - 1), DVec3(0.0)) : DVec3(0.0);
    err = glm::sqrt(var / double(n));
}

/// A pixel's Lr, standard error and spp from its sums (exact: the sum, no
/// error). A value that does not fit a float is zeroed: returns true then.
ACC_HD inline bool resolveSums(const DVec3& sum, const DVec3& sumSq, std::uint32_t n, bool exact, Vec3& mean, Vec3& err,
                               float& spp) {
    mean = err = Vec3(0.0f);
    spp = 0.0f;
    if (exact) mean = Vec3(sum);
    else if (n > 0) {
        DVec3 m, e;
        meanAndError(sum, sumSq, n, m, e);
        mean = Vec3(m);
        err = Vec3(e);
        spp = float(n);
    }
    if (finiteSum(DVec3(mean)) && finiteSum(DVec3(err))) return false;
    mean = err = Vec3(0.0f);  // float overflow of a finite double
    return true;
}

/// Adaptive sampling (render.target_stderr): at the end of round
/// `roundsTaken`, a pixel stops when the relative standard error of its
/// luminance reached the target, or when its next round would pass
/// max_samples.
ACC_HD inline bool roundDone(const DVec3& s1, const DVec3& s2, std::uint32_t n, std::uint32_t roundsTaken,
                             std::uint32_t samples, std::uint32_t maxSamples, double targetStderr) {
    if (std::uint64_t(roundsTaken + 1) * samples > maxSamples) return true;
    if (n < 2) return false;
    DVec3 m, err;
    meanAndError(s1, s2, n, m, err);
    return luminance(Vec3(err)) <= targetStderr * luminance(Vec3(m));
}

}  // namespace accretion
