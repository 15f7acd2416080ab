#include "accretion/lighting/resampling.h"

#include <numeric>

namespace accretion::resampling {

std::vector<double> misWeightsNone(std::span<const double> M) {
    const double total = std::accumulate(M.begin(), M.end(), 0.0);
    std::vector<double> m(M.size());
    for (std::size_t i = 0; i < M.size(); ++i) m[i] = M[i] / total;
    return m;
}

std::vector<double> misWeightsBasic(std::span<const double> M, std::span<const double> p) {
    double Z = 0.0;
    for (std::size_t i = 0; i < M.size(); ++i)
        if (p[i] > 0.0) Z += M[i];
    std::vector<double> m(M.size(), 0.0);
    for (std::size_t i = 0; i < M.size(); ++i)
        if (p[i] > 0.0) m[i] = M[i] / Z;
    return m;
}

std::vector<double> misWeightsPairwise(std::span<const double> M, std::span<const double> p) {
    const double total = std::accumulate(M.begin(), M.end(), 0.0);
    const double k = double(M.size() - 1);
    std::vector<double> m(M.size(), 0.0);
    if (M.size() == 1) {
        m[0] = 1.0;
        return m;
    }
    for (std::size_t j = 1; j < M.size(); ++j) {
        m[0] += pairwiseCanonicalTerm(M[j], p[j], M[0], k, p[0], total);
        m[j] = pairwiseNeighbourWeight(M[j], p[j], M[0], k, p[0], total);
    }
    return m;
}

}  // namespace accretion::resampling
