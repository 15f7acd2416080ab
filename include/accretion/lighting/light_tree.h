#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/particles/particles.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Light-tree importance sampling over point emitters (a binary BVH over the
/// particles with power and spatial bounds, after pbrt-v4's BVHLightSampler
/// and Conty Estevez & Kulla 2018). Each traversal step picks a child with
/// probability proportional to a conservative bound of its contribution at
/// the receiver (power x cosine bound / squared distance bound), so every
/// light whose term is non-zero has a non-zero pdf: the estimator is
/// unbiased. The receiver's own particle gets importance 0 (i != j).
class LightTree {
public:
    LightTree() = default;
    /// Build over the particles' positions and luminance(emission).
    LightTree(const Particles& particles, const ShadingSettings& shading);

    /// Draw a light for the receiver (one uniform per level).
    LightSample sample(const ShadingPoint& sp, Rng& rng) const;
    /// Probability that sample() returns light i at this receiver.
    float pdf(const ShadingPoint& sp, std::uint32_t i) const;

    std::size_t nodeCount() const { return nodes_.size(); }
    std::uint32_t depth() const { return depth_; }
    std::size_t bytes() const { return nodes_.size() * sizeof(Node) + trail_.size() * sizeof(Trail); }

private:
    struct Node {
        Vec3 center;          ///< centre of the bounding sphere of the positions
        float radius;         ///< bounding sphere radius (0 for a leaf)
        float power;          ///< sum of luminance(I) below
        float dmin2;          ///< leaf: the light's squared distance clamp
        std::uint32_t child;  ///< interior: left child (right = child + 1); leaf: light index
        std::uint32_t leaf;   ///< 1 for a leaf
    };
    struct Trail {
        std::uint64_t bits;   ///< bit k: went right at depth k
        std::uint32_t depth;
    };

    void build(std::uint32_t node, std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
               const Particles& particles, std::uint64_t bits, std::uint32_t depth);
    float importance(const Node& node, const ShadingPoint& sp) const;

    std::vector<Node> nodes_;
    std::vector<Trail> trail_;  ///< per light: path from the root
    ShadingModel model_ = ShadingModel::lambert;
    float dmin_ = 0.0f;
    std::uint32_t depth_ = 0;
};

}  // namespace accretion
