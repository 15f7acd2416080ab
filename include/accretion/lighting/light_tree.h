#pragma once
#include <algorithm>
#include <cstdint>
#include <iterator>
#include <utility>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/light_tree_view.h"
#include "accretion/lighting/near_field.h"
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
/// One receiver's descent importances, kept for all its draws: the M
/// candidates drawn at one shading point descend through the same upper
/// levels, and each level's two children cost three square roots and a box
/// test. Direct-mapped on the node index (a collision recomputes); a value
/// is what descentImportance computes for that node, so the draws are those
/// of LightTreeDirect bit for bit (tests/lighting/light_tree_test.cpp). On
/// the CPU only: the GPU's candidate thread keeps no table.
class LightTreeMemo {
public:
    LightTreeMemo() { std::fill(std::begin(node_), std::end(node_), kEmpty); }
    float operator()(const LightTreeView& tree, std::uint32_t n, const ShadingPoint& sp) {
        const std::uint32_t s = (n * 0x9e3779b1u) >> (32 - kBits);  // Fibonacci hashing onto the slots
        if (node_[s] != n) {
            node_[s] = n;
            value_[s] = tree.descentImportance(n, tree.nodes[n].power, sp);
        }
        return value_[s];
    }

private:
    static constexpr std::uint32_t kBits = 7, kEmpty = 0xffffffffu;
    std::uint32_t node_[1u << kBits];
    float value_[1u << kBits];
};

class LightTree {
public:
    LightTree() = default;
    /// Build over the particles' positions and luminance(emission).
    LightTree(const Particles& particles, const ShadingSettings& shading);

    /// Draw a light for the receiver: one uniform per level down to a node of
    /// at most kExactBelow lights, then one among its leaves (LightTreeView::sample).
    LightSample sample(const ShadingPoint& sp, Rng& rng) const { return view().sample(sp, rng); }
    /// The same draw, the receiver's importances recalled from `memo` (one
    /// memo per shading point, for all its draws).
    LightSample sample(const ShadingPoint& sp, Rng& rng, LightTreeMemo& memo) const { return view().sample(sp, rng, memo); }
    /// Probability that sample() returns light i at this receiver.
    float pdf(const ShadingPoint& sp, std::uint32_t i) const;

    // The `split` estimator's near and far fields: nearest, sampleFar and
    // pdfFar are defined beside the near field, in src/lighting/near_field.cpp.

    /// The min(k, N - 1) lights nearest to the receiver other than its own
    /// particle (depth-first, the nearer child first, pruned by the k-th
    /// distance on the nodes' spheres), in tree order with their powers, and
    /// the far cut seen from the receiver (NearField). The renderer finds it
    /// at a particle's centre with the particle's normal, for all its pixels.
    /// The cut has at most `cutNodes` nodes (1..NearField::kMaxCut).
    void nearest(const ShadingPoint& sp, std::uint32_t k, NearField& out, std::uint32_t cutNodes = NearField::kMaxCut) const;
    /// nearest()'s search alone: the min(k, N - 1, NearField::kMaxNear)
    /// lights nearest to sp.x other than sp.self into `lights`, nearest first
    /// (ties: the smaller index first); returns how many. Its first k' are
    /// the search's for any k' <= k, so one search serves every smaller k.
    std::uint32_t nearestLights(const ShadingPoint& sp, std::uint32_t k, std::uint32_t* lights) const;
    /// The near field of these lights (nearest()'s out.light, in any order)
    /// and its far cut of at most `cutNodes` nodes, seen from sp.
    void nearField(const ShadingPoint& sp, const std::uint32_t* lights, std::uint32_t count, NearField& out,
                   std::uint32_t cutNodes = NearField::kMaxCut) const;
    /// Draw a far light (not in `near`): a node of near's cut in proportion
    /// to its weight, then sample()'s descent below it with each node's power
    /// less the power of its near lights (a node of near lights only has
    /// none), ending with one draw among the far leaves of a node of at most
    /// kGatherBelow lights, so the pdf is renormalised over the far lights
    /// exactly. sp may be another point than the one near was found for.
    LightSample sampleFar(const ShadingPoint& sp, const NearField& near, Rng& rng) const;
    /// Probability that sampleFar() returns light i (0 for a near light).
    float pdfFar(const ShadingPoint& sp, const NearField& near, std::uint32_t i) const;

    /// The descent over the node array, as plain data (what the OptiX twin uploads).
    LightTreeView view() const { return {nodes_.data(), static_cast<std::uint32_t>(nodes_.size()), model_}; }
    const std::vector<LightTreeNode>& nodes() const { return nodes_; }
    /// Each light's path from the root (bit k: went right at depth k), for
    /// a search that starts below the root (particle_split's nearestLights).
    std::vector<std::uint64_t> paths() const {
        std::vector<std::uint64_t> out(trail_.size());
        for (std::size_t i = 0; i < trail_.size(); ++i) out[i] = trail_[i].bits;
        return out;
    }
    std::size_t nodeCount() const { return nodes_.size(); }
    std::uint32_t depth() const { return depth_; }
    std::size_t bytes() const { return nodes_.size() * sizeof(Node) + trail_.size() * sizeof(Trail); }

private:
    using Node = LightTreeNode;
    struct Trail {
        std::uint64_t bits;   ///< bit k: went right at depth k
        std::uint32_t depth;
        std::uint32_t leaf;   ///< its leaf node
    };

    void build(std::uint32_t node, std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
               const Particles& particles, std::uint64_t bits, std::uint32_t depth);
    /// LightTreeView::descentImportance and smallNodeLeaves over this tree.
    float descentImportance(std::uint32_t n, float power, const ShadingPoint& sp, float minDist2 = 0.0f,
                            const std::uint32_t* excluded = nullptr, std::uint32_t excludedCount = 0) const {
        return view().descentImportance(n, power, sp, minDist2, excluded, excludedCount);
    }
    static constexpr std::uint32_t kExactBelow = LightTreeView::kExactBelow;
    using SmallNode = LightTreeSmallNode;
    std::uint32_t smallNodeLeaves(std::uint32_t n, const ShadingPoint& sp, SmallNode& out) const {
        return view().smallNodeLeaves(n, sp, out);
    }
    /// The far importances of children c and c + 1, whose near lights are
    /// near.light[lo, mid) and [mid, hi): one step of sampleFar / pdfFar.
    std::pair<float, float> farChildren(std::uint32_t c, const NearField& near, std::uint32_t lo, std::uint32_t mid,
                                        std::uint32_t hi, const ShadingPoint& sp) const;
    /// The far cut of `out` (its near lights found), seen from sp.
    void buildFarCut(const ShadingPoint& sp, std::uint32_t cutNodes, NearField& out) const;
    /// A cut node's weight: its far importance at sp, plus 1e-3 of the bound
    /// without the cosine (never 0 where the node has far power).
    float cutWeight(std::uint32_t n, const NearField& near, std::uint32_t lo, std::uint32_t hi, const ShadingPoint& sp) const;
    /// The far leaves of node n (at most kGatherBelow lights; its near
    /// lights are near.light[lo, hi)) with their importances at sp.
    static constexpr std::uint32_t kGatherBelow = 16;
    struct FarLeaves {
        std::uint32_t leaf[kGatherBelow];
        float importance[kGatherBelow];
        float total;
        std::uint32_t count;
    };
    void farLeaves(std::uint32_t n, const NearField& near, std::uint32_t lo, std::uint32_t hi, const ShadingPoint& sp,
                   FarLeaves& out) const;
    /// The power of a node's far lights (`nearCount` of its lights are near, with `nearPower`).
    static float farPower(const Node& node, std::uint32_t nearCount, double nearPower);
    /// A light's path from the root as a tree-order key (the first step in bit 63).
    static std::uint64_t pathKey(const Trail& t);

    std::vector<Node> nodes_;
    std::vector<Trail> trail_;  ///< per light: path from the root
    ShadingModel model_ = ShadingModel::lambert;
    float dmin_ = 0.0f;
    std::uint32_t depth_ = 0;
};

}  // namespace accretion
