#pragma once
// Why a temporal or spatial reuse offer was kept or refused: the anatomy of
// reuse, counted per pass by the CPU's bridge (stats.json `reuse`, bias and
// tune per configuration).
#include <array>
#include <cstdint>
#include <string_view>

#include "accretion/core/math.h"

namespace accretion {

enum class ReuseOutcome : std::uint8_t {
    sameParticle,   ///< kept: the history or neighbour is on this pixel's particle
    otherParticle,  ///< spatial: kept, on another particle (a screen-space neighbour of a particle is often another one)
    noHistory,      ///< temporal: the particle was not in the previous frame
    offScreen,      ///< reprojected or drawn outside the (lighting) grid
    miss,           ///< spatial: the neighbour pixel hit nothing
    particle,       ///< temporal: refused, the reprojected pixel shows another particle
    normal,         ///< refused: normals further apart than restir.normal_threshold
    depth,          ///< refused: depths further apart than restir.depth_threshold
};
inline constexpr std::size_t kReuseOutcomes = std::size_t(ReuseOutcome::depth) + 1;

/// Names in stats.json, bias's and tune's JSON.
inline constexpr std::array<std::string_view, kReuseOutcomes> kReuseOutcomeNames = {
    "same_particle", "other_particle", "no_history", "off_screen", "miss", "another_particle", "normal", "depth"};

ACC_HD constexpr bool kept(ReuseOutcome o) { return o == ReuseOutcome::sameParticle || o == ReuseOutcome::otherParticle; }

/// One pass's offers by outcome, and how often temporal reuse's M cap bound.
struct ReuseCounts {
    std::array<std::uint64_t, kReuseOutcomes> n{};
    std::uint64_t mCapped = 0;  ///< temporal: kept histories whose M was cut to m_cap x the current M
    void add(ReuseOutcome o) { ++n[std::size_t(o)]; }
    std::uint64_t accepted() const { return n[std::size_t(ReuseOutcome::sameParticle)] + n[std::size_t(ReuseOutcome::otherParticle)]; }
    std::uint64_t offered() const {
        std::uint64_t s = 0;
        for (std::uint64_t v : n) s += v;
        return s;
    }
    ReuseCounts& operator+=(const ReuseCounts& o) {
        for (std::size_t k = 0; k < kReuseOutcomes; ++k) n[k] += o.n[k];
        mCapped += o.mCapped;
        return *this;
    }
};

}  // namespace accretion
