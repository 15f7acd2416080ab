#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// Particles grouped into clusters, one BLAS each (docs/MODEL.md section 2).
struct Clusters {
    std::vector<std::uint32_t> particle;  ///< particle indices, cluster by cluster
    std::vector<std::uint32_t> offset;    ///< cluster c is particle[offset[c] .. offset[c+1])

    std::size_t count() const { return offset.empty() ? 0 : offset.size() - 1; }
    std::span<const std::uint32_t> members(std::size_t c) const {
        return {particle.data() + offset[c], offset[c + 1] - offset[c]};
    }
};

/// Uniform-grid clustering: cubic cells, the finest grid whose non-empty
/// cells hold at least `target` particles on average; cells with more than
/// `target` are split (in Morton order) into equal chunks of at most
/// `target`. Deterministic.
Clusters clusterParticles(std::span<const Vec3> positions, std::uint32_t target);

}  // namespace accretion
