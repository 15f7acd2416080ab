#include "accretion/lighting/light_tree.h"

#include <algorithm>

#include "accretion/core/error.h"

namespace accretion {

LightTree::LightTree(const Particles& particles, const ShadingSettings& shading)
    : model_(shading.model), dmin_(static_cast<float>(shading.dmin)) {
    const auto n = static_cast<std::uint32_t>(particles.size());
    if (n == 0) return;
    std::vector<std::uint32_t> ids(n);
    for (std::uint32_t i = 0; i < n; ++i) ids[i] = i;
    nodes_.reserve(2 * std::size_t(n) - 1);
    trail_.resize(n);
    nodes_.resize(1);
    build(0, ids, 0, n, particles, 0, 0);
}

/// Median split on the longest axis of the positions' box. Children are
/// allocated as a pair (right = child + 1) before recursing.
void LightTree::build(std::uint32_t node, std::vector<std::uint32_t>& ids, std::uint32_t begin, std::uint32_t end,
                      const Particles& particles, std::uint64_t bits, std::uint32_t depth) {
    depth_ = std::max(depth_, depth);
    if (end - begin == 1) {
        const std::uint32_t i = ids[begin];
        const float dmin = std::max(particles.radius[i], dmin_);
        ACC_CHECK(depth < 64);
        nodes_[node] = Node{particles.position[i], 0.0f, luminance(particles.emission[i]), dmin * dmin, i, 1,
                             particles.position[i], particles.position[i]};
        trail_[i] = Trail{bits, depth, node};
        return;
    }
    Vec3 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    double power = 0.0;
    for (std::uint32_t k = begin; k < end; ++k) {
        lo = glm::min(lo, particles.position[ids[k]]);
        hi = glm::max(hi, particles.position[ids[k]]);
        power += luminance(particles.emission[ids[k]]);
    }
    const Vec3 extent = hi - lo;
    const int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(ids.begin() + begin, ids.begin() + mid, ids.begin() + end, [&](std::uint32_t a, std::uint32_t b) {
        return particles.position[a][axis] < particles.position[b][axis];
    });
    const Vec3 center = 0.5f * (lo + hi);
    // Conservative sphere: half the box diagonal, widened for float rounding.
    const float radius = 0.5f * glm::length(extent) * (1.0f + 1e-5f) + 1e-6f * glm::length(center);
    const auto child = static_cast<std::uint32_t>(nodes_.size());
    nodes_[node] = Node{center, radius, static_cast<float>(power), 0.0f, child, end - begin, lo, hi};
    nodes_.resize(nodes_.size() + 2);
    build(child, ids, begin, mid, particles, bits, depth + 1);
    build(child + 1, ids, mid, end, particles, bits | (std::uint64_t(1) << depth), depth + 1);
}

float LightTree::importance(const Node& node, float power, const ShadingPoint& sp, float minDist2) const {
    if (node.count == 1) {
        if (node.child == sp.self || !(power > 0.0f)) return 0.0f;
        const Vec3 delta = node.center - sp.x;
        const float d2 = glm::dot(delta, delta);
        float cosTerm = 1.0f;
        if (model_ != ShadingModel::isotropic) {
            if (!(d2 > 0.0f)) return 0.0f;
            cosTerm = glm::dot(sp.n, delta) / std::sqrt(d2);
            if (!(cosTerm > 0.0f)) return 0.0f;
        }
        return power * cosTerm / std::max(d2, node.dmin2);
    }
    if (!(power > 0.0f)) return 0.0f;
    if (model_ != ShadingModel::isotropic) {
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
    if (model_ != ShadingModel::isotropic && d2 > r2) {
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

float LightTree::descentImportance(std::uint32_t n, float power, const ShadingPoint& sp, float minDist2,
                                   const std::uint32_t* excluded, std::uint32_t excludedCount) const {
    const Node& node = nodes_[n];
    if (node.count == 1 || node.count > kExactBelow) return importance(node, power, sp, minDist2);
    if (!(power > 0.0f)) return 0.0f;
    float sum = 0.0f;
    std::uint32_t stack[2 * kExactBelow], top = 0;
    stack[top++] = n;
    while (top > 0) {
        const Node& m = nodes_[stack[--top]];
        if (m.count > 1) {
            stack[top++] = m.child;
            stack[top++] = m.child + 1;
            continue;
        }
        if (std::find(excluded, excluded + excludedCount, m.child) != excluded + excludedCount) continue;
        sum += importance(m, m.power, sp);
    }
    return sum;
}

std::uint32_t LightTree::smallNodeLeaves(std::uint32_t n, const ShadingPoint& sp, SmallNode& out) const {
    std::uint32_t stack[2 * kExactBelow], top = 0, count = 0;
    stack[top++] = n;
    out.total = 0.0f;
    // The order of descentImportance's sum, so that the total is its value.
    while (top > 0) {
        const std::uint32_t k = stack[--top];
        const Node& m = nodes_[k];
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

LightSample LightTree::sample(const ShadingPoint& sp, Rng& rng) const {
    if (nodes_.empty()) return {kNoLightSample, 0.0f};
    std::uint32_t n = 0;
    float pdf = 1.0f;
    while (nodes_[n].count > kExactBelow) {
        const std::uint32_t c = nodes_[n].child;
        const float a = descentImportance(c, nodes_[c].power, sp);
        const float b = descentImportance(c + 1, nodes_[c + 1].power, sp);
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
    if (nodes_[n].count > 1) {
        // A node of at most kExactBelow lights: one draw among its leaves in
        // proportion to their importances (the binary descent below it with
        // exact sums gives each the same probability, at one uniform).
        SmallNode leaves;
        const std::uint32_t count = smallNodeLeaves(n, sp, leaves);
        if (!(leaves.total > 0.0f)) return {kNoLightSample, 0.0f};
        const float target = rng.uniform() * leaves.total;
        std::uint32_t k = 0;
        float run = leaves.importance[0];
        while (k + 1 < count && (run <= target || leaves.importance[k] == 0.0f)) run += leaves.importance[++k];
        while (leaves.importance[k] == 0.0f && k > 0) --k;  // rounding at the top end: the last leaf with a term
        pdf *= leaves.importance[k] / leaves.total;
        n = leaves.leaf[k];
    }
    if (!(pdf > 0.0f)) return {kNoLightSample, 0.0f};
    return {nodes_[n].child, pdf};
}

float LightTree::pdf(const ShadingPoint& sp, std::uint32_t i) const {
    if (i >= trail_.size()) return 0.0f;
    const Trail t = trail_[i];
    std::uint32_t n = 0;
    float pdf = 1.0f;
    for (std::uint32_t k = 0; k < t.depth && nodes_[n].count > kExactBelow; ++k) {
        const std::uint32_t c = nodes_[n].child;
        const float a = descentImportance(c, nodes_[c].power, sp);
        const float b = descentImportance(c + 1, nodes_[c + 1].power, sp);
        if (!(a + b > 0.0f)) return 0.0f;
        const bool right = (t.bits >> k) & 1u;
        const float pa = a / (a + b);
        pdf *= right ? 1.0f - pa : pa;
        n = right ? c + 1 : c;
    }
    if (nodes_[n].count > 1) {
        SmallNode leaves;
        const std::uint32_t count = smallNodeLeaves(n, sp, leaves);
        if (!(leaves.total > 0.0f)) return 0.0f;
        for (std::uint32_t k = 0; k < count; ++k)
            if (leaves.leaf[k] == t.leaf) return pdf * (leaves.importance[k] / leaves.total);
        return 0.0f;
    }
    return pdf;
}

}  // namespace accretion
