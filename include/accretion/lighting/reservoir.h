#pragma once
#include <cstdint>
#include <limits>

#include "accretion/core/math.h"

namespace accretion {

inline constexpr std::uint32_t kNoLight = 0xffffffffu;

/// Weighted reservoir of one light sample (Bitterli et al. 2020, Alg. 2):
/// streams candidates, keeps y with probability w_y / w_sum.
/// W = w_sum / (M p_hat(y)) is the contribution weight (docs/MODEL.md section 4;
/// not w_sum / M: docs/MODEL.md section 7).
struct Reservoir {
    std::uint32_t y = kNoLight;  ///< selected light
    float w_sum = 0.0f;          ///< sum of resampling weights
    float p_hat = 0.0f;          ///< target function of y at this pixel
    std::uint32_t M = 0;         ///< candidates seen
    float W = 0.0f;              ///< contribution weight (after finalize)

    /// Stream candidate x with resampling weight w and target p_hat_x; u uniform in [0,1).
    ACC_HD bool update(std::uint32_t x, float w, float p_hat_x, float u) {
        w_sum += w;
        ++M;
        if (w > 0.0f && u * w_sum < w) {
            y = x;
            p_hat = p_hat_x;
            return true;
        }
        return false;
    }

    /// Merge a reservoir of M_other candidates whose sample x carries
    /// resampling weight w (p_hat(x) W M_other for a finalized one, docs/MODEL.md
    /// section 4): keeps x with probability w / w_sum.
    ACC_HD bool merge(std::uint32_t x, float w, float p_hat_x, std::uint32_t M_other, float u) {
        const bool kept = update(x, w, p_hat_x, u);
        M += M_other - 1;
        return kept;
    }

    /// W = w_sum / (M p_hat(y)), 0 when nothing was selected.
    ACC_HD void finalize() { W = (y != kNoLight && p_hat > 0.0f && M > 0) ? w_sum / (float(M) * p_hat) : 0.0f; }
};

}  // namespace accretion
