#include "accretion/lighting/alias_table.h"

#include <cmath>

#include "accretion/core/error.h"

namespace accretion {

AliasTable::AliasTable(std::span<const float> weights) {
    const std::size_t n = weights.size();
    ACC_CHECK(n > 0 && n <= 0xffffffffull);
    for (float w : weights) {
        ACC_CHECK(std::isfinite(w) && w >= 0.0f);
        total_ += w;
    }
    ACC_CHECK(total_ > 0.0);
    prob_.resize(n);
    alias_.resize(n);
    pmf_.resize(n);
    std::vector<double> scaled(n);
    std::vector<std::uint32_t> small, large;
    for (std::size_t i = 0; i < n; ++i) {
        pmf_[i] = static_cast<float>(weights[i] / total_);
        scaled[i] = weights[i] / total_ * double(n);
        (scaled[i] < 1.0 ? small : large).push_back(static_cast<std::uint32_t>(i));
    }
    // Vose: pair each under-full bucket with an over-full donor.
    while (!small.empty() && !large.empty()) {
        const std::uint32_t s = small.back(), l = large.back();
        small.pop_back();
        prob_[s] = static_cast<float>(scaled[s]);
        alias_[s] = l;
        scaled[l] = (scaled[l] + scaled[s]) - 1.0;
        if (scaled[l] < 1.0) {
            large.pop_back();
            small.push_back(l);
        }
    }
    for (std::uint32_t i : large) { prob_[i] = 1.0f; alias_[i] = i; }
    for (std::uint32_t i : small) { prob_[i] = 1.0f; alias_[i] = i; }  // rounding leftovers
}

}  // namespace accretion
