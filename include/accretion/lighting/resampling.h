#pragma once
// The resampling core of ReSTIR DI as pure functions of plain values (the
// reservoir itself, update and merge, is in reservoir.h). The passes in
// src/render/restir/ call these; tests/lighting/resampling_test.cpp checks
// them directly. Notation of docs/MODEL.md section 4: domain i (a pixel of
// this or the previous frame) offers a reservoir of M_i candidates whose
// sample y has target p_i(y) in its own domain; domain 0 is the canonical
// one (the current pixel, target p_c).
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/lighting/reservoir.h"

namespace accretion::resampling {

/// The neighbour test of temporal and spatial reuse: the neighbour's surface
/// (normal nq, depth dq) faces like the receiver's (n, d) and lies at a
/// similar depth, relative to the receiver's.
ACC_HD inline bool similarSurface(const Vec3& n, float d, const Vec3& nq, float dq, float normalThreshold,
                           float depthThreshold) {
    return glm::dot(n, nq) >= normalThreshold && std::fabs(d - dq) <= depthThreshold * d;
}

/// similarSurface, saying which test refused: `accepted` when both pass,
/// else normal (tested first) or depth.
template <class Outcome>
ACC_HD inline Outcome surfaceOutcome(const Vec3& n, float d, const Vec3& nq, float dq, float normalThreshold, float depthThreshold,
                                     Outcome accepted) {
    if (!(glm::dot(n, nq) >= normalThreshold)) return Outcome::normal;
    if (!(std::fabs(d - dq) <= depthThreshold * d)) return Outcome::depth;
    return accepted;
}

/// Pairwise MIS (Bitterli 2022, ch. 9.1.3): each of the k = n - 1
/// neighbours forms a two-strategy balance heuristic with the canonical
/// domain, whose confidence M_c is split over the k pairs.
/// Term of neighbour j in the weight of a sample y held by the canonical
/// reservoir: pj = p_j(y), pc = p_c(y).
ACC_HD inline double pairwiseCanonicalTerm(double Mj, double pj, double Mc, double k, double pc, double Mtotal) {
    const double a = Mj * pj, b = Mc / k * pc;
    return (Mj + Mc / k) / Mtotal * (a + b > 0.0 ? b / (a + b) : 0.0);
}

/// Weight of a sample y held by neighbour i: pi = p_i(y), pc = p_c(y).
ACC_HD inline double pairwiseNeighbourWeight(double Mi, double pi, double Mc, double k, double pc, double Mtotal) {
    const double a = Mi * pi, b = Mc / k * pc;
    return (Mi + Mc / k) / Mtotal * (a + b > 0.0 ? a / (a + b) : 0.0);
}

/// The `basic` normalisation Z of a combined reservoir: the M of the domain
/// that produced y, plus the M of every other domain that counts (its
/// p_hat of y is non-zero and, with basic_visibility, it sees y), summed
/// in domain order. W = w_sum / (Z p_hat(y)).
ACC_HD inline double basicNormalization(const std::uint32_t* M, const std::uint8_t* counts, std::size_t n,
                                        std::size_t chosen) {
    double Z = M[chosen];
    for (std::size_t i = 0; i < n; ++i)
        if (i != chosen && counts[i]) Z += M[i];
    return Z;
}
inline double basicNormalization(std::span<const std::uint32_t> M, std::span<const std::uint8_t> counts,
                                 std::size_t chosen) {
    return basicNormalization(M.data(), counts.data(), M.size(), chosen);
}

/// The MIS weight m_i(y) of every domain for one sample y, given each
/// domain's M_i and target p_i(y) (index 0: canonical), under each bias
/// correction. `none`: M_i / sum M (sums to 1 only where every p_i(y) > 0:
/// the bias); `basic`: M_i / Z over the domains with p_i(y) > 0; `pairwise`:
/// the terms above. Each sums to 1 over the domains that can produce y.
std::vector<double> misWeightsNone(std::span<const double> M);
std::vector<double> misWeightsBasic(std::span<const double> M, std::span<const double> p);
std::vector<double> misWeightsPairwise(std::span<const double> M, std::span<const double> p);

}  // namespace accretion::resampling
