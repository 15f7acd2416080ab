#pragma once
// The light tree's descent as plain data over its node array: what the CPU's
// LightTree and the OptiX twin's candidate kernel both run (ACC_HD), so a
// candidate drawn from the tree on the GPU is the CPU's draw.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/geometry/shading_point.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// A node of the light tree: a binary BVH over point emitters with their power.
struct LightTreeNode {
    Vec3 center;          ///< centre of the bounding sphere of the positions
    float radius;         ///< bounding sphere radius (0 for a leaf)
    float power;          ///< sum of luminance(I) below
    float dmin2;          ///< leaf: the light's squared distance clamp
    std::uint32_t child;  ///< interior: left child (right = child + 1); leaf: light index
    std::uint32_t count;  ///< lights below (1: a leaf)
    Vec3 lo, hi;          ///< box of the positions below (a leaf: its position)
};

/// The leaves of a node of at most LightTreeView::kExactBelow lights, with their importances.
struct LightTreeSmallNode {
    static constexpr std::uint32_t kCapacity = 8;
    std::uint32_t leaf[kCapacity];
    float importance[kCapacity];
    float total;
};

/// The entry of `importance[0, count)` (their sum > 0) that `target`, a
/// uniform times that sum, falls on: each with probability in proportion
/// to its importance; where rounding at the top end lands past the last
/// non-zero one, that one (an entry of importance 0 is never picked).
ACC_HD inline std::uint32_t pickLeaf(const float* importance, std::uint32_t count, float target) {
    std::uint32_t k = 0;
    float run = importance[0];
    while (k + 1 < count && (run <= target || importance[k] == 0.0f)) run += importance[++k];
    while (importance[k] == 0.0f && k > 0) --k;
    return k;
}

struct LightTreeView;

/// The importance sample() weighs a child by, computed where it is asked
/// for (descentImportance at the node's own power): the GPU's way, and the
/// CPU's for a single draw. LightTreeMemo (light_tree.h) gives the same
/// values from a receiver's table for many draws.
struct LightTreeDirect {
    ACC_HD float operator()(const LightTreeView& tree, std::uint32_t n, const ShadingPoint& sp) const;
};

struct LightTreeView {
    static constexpr std::uint32_t kExactBelow = LightTreeSmallNode::kCapacity;
    const LightTreeNode* nodes = nullptr;
    std::uint32_t nodeCount = 0;
    ShadingModel model = ShadingModel::lambert;

    /// The node's bound of the terms below it with `power` in place of its
    /// own, every light below being at least sqrt(minDist2) away: power x a
    /// cosine bound / a squared distance bound, 0 for the receiver's own
    /// particle and for a box wholly behind the receiver's plane.
    ACC_HD float importance(const LightTreeNode& node, float power, const ShadingPoint& sp, float minDist2 = 0.0f) const {
        if (node.count == 1) {
            if (node.child == sp.self || !(power > 0.0f)) return 0.0f;
            const Vec3 delta = node.center - sp.x;
            const float d2 = glm::dot(delta, delta);
            float cosTerm = 1.0f;
            if (model != ShadingModel::isotropic) {
                if (!(d2 > 0.0f)) return 0.0f;
                cosTerm = glm::dot(sp.n, delta) / std::sqrt(d2);
                if (!(cosTerm > 0.0f)) return 0.0f;
            }
            return power * cosTerm / std::max(d2, node.dmin2);
        }
        if (!(power > 0.0f)) return 0.0f;
        if (model != ShadingModel::isotropic) {
            // The box behind the receiver's plane (n . (p - x) <= 0 at its
            // farthest corner along n): no light below has a term. A slack of
            // 1e-5 of the corner's scale keeps a light that rounds to the plane.
            const Vec3 a = node.lo - sp.x, b = node.hi - sp.x;
            const float front = std::max(sp.n.x * a.x, sp.n.x * b.x) + std::max(sp.n.y * a.y, sp.n.y * b.y) +
                                std::max(sp.n.z * a.z, sp.n.z * b.z);
            const float scale = glm::dot(glm::abs(sp.n), glm::max(glm::abs(a), glm::abs(b)));
            if (!(front > -1e-5f * scale)) return 0.0f;
        }
        const Vec3 delta = node.center - sp.x;
        const float d2 = glm::dot(delta, delta);
        const float r2 = node.radius * node.radius;
        float cosBound = 1.0f;
        if (model != ShadingModel::isotropic && d2 > r2) {
            // cos(max(0, theta_n - theta_b)): theta_n between n and the centre,
            // theta_b the half-angle the bounding sphere subtends.
            const float d = std::sqrt(d2);
            const float cosN = glm::dot(sp.n, delta) / d;
            const float sinB = node.radius / d;
            const float cosB = std::sqrt(std::max(0.0f, 1.0f - sinB * sinB));
            if (cosN < cosB) {
                const float sinN = std::sqrt(std::max(0.0f, 1.0f - cosN * cosN));
                cosBound = cosN * cosB + sinN * sinB;
                if (!(cosBound > 0.0f)) return 0.0f;
            }
        }
        return power * cosBound / std::max(std::max(d2, r2), minDist2);
    }

    /// The importance a descent gives node n: importance() for a large node;
    /// for a node of at most kExactBelow lights, the sum of its leaves' own
    /// (the lights in `excluded` left out), so that a descent never ends
    /// below it on lights that all have no term.
    ACC_HD float descentImportance(std::uint32_t n, float power, const ShadingPoint& sp, float minDist2 = 0.0f,
                                   const std::uint32_t* excluded = nullptr, std::uint32_t excludedCount = 0) const {
        const LightTreeNode& node = nodes[n];
        if (node.count == 1 || node.count > kExactBelow) return importance(node, power, sp, minDist2);
        if (!(power > 0.0f)) return 0.0f;
        float sum = 0.0f;
        std::uint32_t stack[2 * kExactBelow], top = 0;
        stack[top++] = n;
        while (top > 0) {
            const LightTreeNode& m = nodes[stack[--top]];
            if (m.count > 1) {
                stack[top++] = m.child;
                stack[top++] = m.child + 1;
                continue;
            }
            bool skip = false;
            for (std::uint32_t e = 0; e < excludedCount && !skip; ++e) skip = excluded[e] == m.child;
            if (!skip) sum += importance(m, m.power, sp);
        }
        return sum;
    }

    /// The leaves of node n (at most kExactBelow lights) with their
    /// importances, in the order of descentImportance's sum.
    ACC_HD std::uint32_t smallNodeLeaves(std::uint32_t n, const ShadingPoint& sp, LightTreeSmallNode& out) const {
        std::uint32_t stack[2 * kExactBelow], top = 0, count = 0;
        stack[top++] = n;
        out.total = 0.0f;
        while (top > 0) {
            const std::uint32_t k = stack[--top];
            const LightTreeNode& m = nodes[k];
            if (m.count > 1) {
                stack[top++] = m.child;
                stack[top++] = m.child + 1;
                continue;
            }
            out.leaf[count] = k;
            out.importance[count] = importance(m, m.power, sp);
            out.total += out.importance[count];
            ++count;
        }
        return count;
    }

    /// Draw a light for the receiver: one uniform per level down to a node of
    /// at most kExactBelow lights, then one among its leaves in proportion to
    /// their importances (the binary descent below it with exact sums gives
    /// each the same probability, at one uniform). `importanceOf(tree, n, sp)`
    /// gives descentImportance(n, nodes[n].power, sp), computed or recalled.
    template <class R, class Importance = LightTreeDirect>
    ACC_HD LightSample sample(const ShadingPoint& sp, R& rng, Importance&& importanceOf = Importance{}) const {
        if (nodeCount == 0) return {kNoLightSample, 0.0f};
        std::uint32_t n = 0;
        float pdf = 1.0f;
        while (nodes[n].count > kExactBelow) {
            const std::uint32_t c = nodes[n].child;
            const float a = importanceOf(*this, c, sp);
            const float b = importanceOf(*this, c + 1, sp);
            const float u = rng.uniform();
            if (!(a + b > 0.0f)) return {kNoLightSample, 0.0f};
            const float pa = a / (a + b);
            if (u < pa) {
                n = c;
                pdf *= pa;
            } else {
                n = c + 1;
                pdf *= 1.0f - pa;
            }
        }
        if (nodes[n].count > 1) {
            LightTreeSmallNode leaves;
            const std::uint32_t count = smallNodeLeaves(n, sp, leaves);
            if (!(leaves.total > 0.0f)) return {kNoLightSample, 0.0f};
            const std::uint32_t k = pickLeaf(leaves.importance, count, rng.uniform() * leaves.total);
            pdf *= leaves.importance[k] / leaves.total;
            n = leaves.leaf[k];
        }
        if (!(pdf > 0.0f)) return {kNoLightSample, 0.0f};
        return {nodes[n].child, pdf};
    }
};

ACC_HD inline float LightTreeDirect::operator()(const LightTreeView& tree, std::uint32_t n, const ShadingPoint& sp) const {
    return tree.descentImportance(n, tree.nodes[n].power, sp);
}

}  // namespace accretion
