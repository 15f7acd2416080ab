#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// What sampling reads of an alias table, as pointers (the OptiX twin
/// uploads AliasTable's arrays and samples them through this view).
struct AliasTableView {
    const float* prob = nullptr;
    const std::uint32_t* alias = nullptr;
    const float* pmf = nullptr;

    /// Index for a uniform bucket in [0, size) and a coin u in [0, 1).
    ACC_HD std::uint32_t sample(std::uint32_t bucket, float u) const { return u < prob[bucket] ? bucket : alias[bucket]; }
};

/// Walker/Vose alias table: O(1) sampling of index i with pmf w_i / sum w.
class AliasTable {
public:
    AliasTable() = default;
    /// Weights must be finite and >= 0 with a positive sum.
    explicit AliasTable(std::span<const float> weights);

    /// Sample with a uniform bucket in [0, size()) and a coin u in [0, 1).
    std::uint32_t sample(std::uint32_t bucket, float u) const { return view().sample(bucket, u); }
    /// Probability of index i.
    float pmf(std::uint32_t i) const { return pmf_[i]; }
    std::uint32_t size() const { return static_cast<std::uint32_t>(prob_.size()); }
    double total() const { return total_; }
    /// The arrays, for a device copy.
    const std::vector<float>& probabilities() const { return prob_; }
    const std::vector<std::uint32_t>& aliases() const { return alias_; }
    const std::vector<float>& pmfs() const { return pmf_; }
    AliasTableView view() const { return {prob_.data(), alias_.data(), pmf_.data()}; }

private:
    std::vector<float> prob_;
    std::vector<std::uint32_t> alias_;
    std::vector<float> pmf_;
    double total_ = 0.0;
};

}  // namespace accretion
