#pragma once
#include <cstdint>
#include <span>
#include <vector>

namespace accretion {

/// Walker/Vose alias table: O(1) sampling of index i with pmf w_i / sum w.
class AliasTable {
public:
    AliasTable() = default;
    /// Weights must be finite and >= 0 with a positive sum.
    explicit AliasTable(std::span<const float> weights);

    /// Sample with a uniform bucket in [0, size()) and a coin u in [0, 1).
    std::uint32_t sample(std::uint32_t bucket, float u) const {
        return u < prob_[bucket] ? bucket : alias_[bucket];
    }
    /// Probability of index i.
    float pmf(std::uint32_t i) const { return pmf_[i]; }
    std::uint32_t size() const { return static_cast<std::uint32_t>(prob_.size()); }
    double total() const { return total_; }

private:
    std::vector<float> prob_;
    std::vector<std::uint32_t> alias_;
    std::vector<float> pmf_;
    double total_ = 0.0;
};

}  // namespace accretion
