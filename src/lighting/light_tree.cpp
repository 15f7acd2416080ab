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
