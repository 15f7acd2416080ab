// The light tree's near/far split (lighting/near_field.h): the k nearest
// lights of a receiver, and the far lights drawn with them taken out.
#include <algorithm>
#include <utility>

#include "accretion/core/error.h"
#include "accretion/lighting/light_tree.h"

namespace accretion {

std::uint64_t LightTree::pathKey(const Trail& t) {
    std::uint64_t key = 0;
    for (std::uint32_t k = 0; k < t.depth; ++k) key |= ((t.bits >> k) & 1u) << (63 - k);
    return key;
}

float LightTree::farPower(const Node& node, std::uint32_t nearCount, double nearPower) {
    if (nearCount == 0) return node.power;
    if (nearCount >= node.count) return 0.0f;
    // Some light below is far: keep the node reachable even where float
    // cancellation (a bright near light beside faint far ones) leaves nothing.
    return std::max(static_cast<float>(double(node.power) - nearPower), node.power * 1e-6f);
}

void LightTree::nearest(const ShadingPoint& sp, std::uint32_t k, NearField& out, std::uint32_t cutNodes) const {
    out.count = 0;
    out.power[0] = 0.0;
    if (nodes_.empty()) return;
    // The receiver's own particle joins them: it gives no term, and the far
    // sampler must not spend draws on it.
    std::uint32_t lights[NearField::kMaxLights];
    std::uint32_t found = nearestLights(sp, k, lights);
    if (sp.self < trail_.size()) lights[found++] = sp.self;
    nearField(sp, lights, found, out, cutNodes);
}

std::uint32_t LightTree::nearestLights(const ShadingPoint& sp, std::uint32_t k, std::uint32_t* lights) const {
    constexpr std::uint32_t kNoSeed = 0xffffffffu;
    k = std::min(k, NearField::kMaxNear);
    if (nodes_.empty()) return 0;
    // The best so far as a max-heap on squared distance (ties: the larger
    // index is dropped first).
    struct Found {
        float d2;
        std::uint32_t light;
        bool operator<(const Found& o) const { return d2 < o.d2 || (d2 == o.d2 && light < o.light); }
    };
    Found best[NearField::kMaxLights];
    std::uint32_t found = 0;
    // Depth-first, the nearer child first, pruned by the k-th distance.
    struct Pending {
        std::uint32_t node;
        float bound;  ///< squared distance from x to the node's sphere
    };
    Pending stack[2 * 64 + 2];
    std::uint32_t top = 0;
    const auto sphereBound = [&](const Node& n) {
        const float d = glm::length(n.center - sp.x) - n.radius;
        return d > 0.0f ? d * d : 0.0f;
    };
    // One pruned depth-first search below `root`, skipping the subtree `skip`.
    const auto search = [&](std::uint32_t root, std::uint32_t skip) {
        top = 0;
        stack[top++] = {root, sphereBound(nodes_[root])};
        while (top > 0) {
            const Pending p = stack[--top];
            if (p.node == skip || (found == k && !(p.bound <= best[0].d2))) continue;
            const Node& n = nodes_[p.node];
            if (n.count == 1) {
                if (n.child == sp.self) continue;
                const Vec3 delta = n.center - sp.x;
                const Found f{glm::dot(delta, delta), n.child};
                if (found < k) {
                    best[found++] = f;
                    std::push_heap(best, best + found);
                } else if (f < best[0]) {
                    std::pop_heap(best, best + found);
                    best[found - 1] = f;
                    std::push_heap(best, best + found);
                }
                continue;
            }
            const Pending a{n.child, sphereBound(nodes_[n.child])}, b{n.child + 1, sphereBound(nodes_[n.child + 1])};
            // Pushed far first, so the near one is popped first.
            ACC_CHECK(top + 2 <= std::size(stack));
            stack[top++] = a.bound <= b.bound ? b : a;
            stack[top++] = a.bound <= b.bound ? a : b;
        }
    };
    // First the smallest subtree on the receiver's path that holds k others
    // (the tree's neighbours are spatial ones), so that the search from the
    // root starts with a tight k-th distance and skips that subtree.
    std::uint32_t seed = 0;
    if (k > 0 && sp.self < trail_.size()) {
        const Trail t = trail_[sp.self];
        for (std::uint32_t d = 0; d < t.depth; ++d) {
            const std::uint32_t next = nodes_[seed].child + ((t.bits >> d) & 1u);
            if (nodes_[next].count <= k) break;
            seed = next;
        }
    }
    if (k > 0) {
        search(seed, kNoSeed);
        if (seed != 0) search(0, seed);
    }
    std::sort_heap(best, best + found);  // nearest first, in the heap's order
    for (std::uint32_t j = 0; j < found; ++j) lights[j] = best[j].light;
    return found;
}

void LightTree::nearField(const ShadingPoint& sp, const std::uint32_t* lights, std::uint32_t count, NearField& out,
                          std::uint32_t cutNodes) const {
    ACC_CHECK(count <= NearField::kMaxLights);
    // Tree order, with the prefix sums of the powers.
    std::pair<std::uint64_t, std::uint32_t> order[NearField::kMaxLights];
    for (std::uint32_t j = 0; j < count; ++j) order[j] = {pathKey(trail_[lights[j]]), lights[j]};
    std::sort(order, order + count);
    out.count = count;
    out.power[0] = 0.0;
    out.radius2 = 0.0f;
    for (std::uint32_t j = 0; j < count; ++j) {
        const Node& leaf = nodes_[trail_[order[j].second].leaf];
        out.light[j] = order[j].second;
        out.key[j] = order[j].first;
        out.power[j + 1] = out.power[j] + double(leaf.power);
        const Vec3 delta = leaf.center - sp.x;
        out.radius2 = std::max(out.radius2, glm::dot(delta, delta));
    }
    buildFarCut(sp, cutNodes, out);
}

namespace {

/// The first of the near lights [lo, hi) (one node's, in tree order) that
/// lies right of the node's split at `depth`.
/// The keys of [lo, hi) share their first `depth` steps (they lie below one
/// node) and are sorted, so those going left come first: a binary search,
/// not a scan (at k = 1024 a scan was most of a far sample's cost).
std::uint32_t splitNear(const NearField& near, std::uint32_t lo, std::uint32_t hi, std::uint32_t depth) {
    const std::uint64_t bit = std::uint64_t(1) << (63 - depth);
    const std::uint64_t* first = std::partition_point(near.key + lo, near.key + hi, [bit](std::uint64_t k) { return !(k & bit); });
    return static_cast<std::uint32_t>(first - near.key);
}

}  // namespace

std::pair<float, float> LightTree::farChildren(std::uint32_t c, const NearField& near, std::uint32_t lo, std::uint32_t mid,
                                               std::uint32_t hi, const ShadingPoint& sp) const {
    return {descentImportance(c, farPower(nodes_[c], mid - lo, near.power[mid] - near.power[lo]), sp, near.radius2,
                              near.light + lo, mid - lo),
            descentImportance(c + 1, farPower(nodes_[c + 1], hi - mid, near.power[hi] - near.power[mid]), sp, near.radius2,
                              near.light + mid, hi - mid)};
}

float LightTree::cutWeight(std::uint32_t n, const NearField& near, std::uint32_t lo, std::uint32_t hi,
                           const ShadingPoint& sp) const {
    const Node& node = nodes_[n];
    const float far = farPower(node, hi - lo, near.power[hi] - near.power[lo]);
    if (!(far > 0.0f)) return 0.0f;
    LightTreeView flat = view();
    flat.model = ShadingModel::isotropic;
    const float bound = flat.importance(node, far, sp, near.radius2);
    if (model_ != ShadingModel::lambert) return bound;  // a normal per pixel: no cosine shared by the particle
    return view().importance(node, far, sp, near.radius2) + 1e-3f * bound;
}

void LightTree::buildFarCut(const ShadingPoint& sp, std::uint32_t cutNodes, NearField& out) const {
    ACC_CHECK(cutNodes >= 1 && cutNodes <= NearField::kMaxCut);
    out.cutCount = 0;
    out.cutTotal = 0.0f;
    if (nodes_.empty()) return;
    struct Open {
        float weight;
        std::uint32_t node, lo, hi, depth;
        bool operator<(const Open& o) const { return weight < o.weight || (weight == o.weight && node > o.node); }
    };
    Open open[NearField::kMaxCut];
    std::uint32_t count = 0;
    const auto offer = [&](std::uint32_t n, std::uint32_t lo, std::uint32_t hi, std::uint32_t depth) {
        const float w = cutWeight(n, out, lo, hi, sp);
        if (!(w > 0.0f)) return;
        open[count++] = {w, n, lo, hi, depth};
        std::push_heap(open, open + count);
    };
    const auto keep = [&](const Open& o) {
        const std::uint32_t c = out.cutCount++;
        out.cutNode[c] = o.node;
        out.cutWeight[c] = o.weight;
        out.cutLo[c] = static_cast<std::uint16_t>(o.lo);
        out.cutHi[c] = static_cast<std::uint16_t>(o.hi);
        out.cutDepth[c] = static_cast<std::uint8_t>(o.depth);
    };
    offer(0, 0, out.count, 0);
    // Refine where the weight is largest: each split adds at most one node.
    while (count > 0 && count + out.cutCount < cutNodes) {
        std::pop_heap(open, open + count);
        const Open o = open[--count];
        const Node& node = nodes_[o.node];
        if (node.count == 1) {
            keep(o);
            continue;
        }
        const std::uint32_t mid = splitNear(out, o.lo, o.hi, o.depth);
        offer(node.child, o.lo, mid, o.depth + 1);
        offer(node.child + 1, mid, o.hi, o.depth + 1);
    }
    for (std::uint32_t k = 0; k < count; ++k) keep(open[k]);
    float run = 0.0f;
    for (std::uint32_t c = 0; c < out.cutCount; ++c) out.cutCdf[c] = run += out.cutWeight[c];
    out.cutTotal = run;
}

void LightTree::farLeaves(std::uint32_t n, const NearField& near, std::uint32_t lo, std::uint32_t hi, const ShadingPoint& sp,
                          FarLeaves& out) const {
    std::uint32_t stack[2 * kGatherBelow], top = 0;
    stack[top++] = n;
    out.total = 0.0f;
    out.count = 0;
    while (top > 0) {
        const std::uint32_t k = stack[--top];
        const Node& m = nodes_[k];
        if (m.count > 1) {
            stack[top++] = m.child;
            stack[top++] = m.child + 1;
            continue;
        }
        if (std::find(near.light + lo, near.light + hi, m.child) != near.light + hi) continue;
        out.leaf[out.count] = k;
        out.importance[out.count] = view().importance(m, m.power, sp);
        out.total += out.importance[out.count];
        ++out.count;
    }
}

LightSample LightTree::sampleFar(const ShadingPoint& sp, const NearField& near, Rng& rng) const {
    if (near.cutCount == 0) return {kNoLightSample, 0.0f};
    const float target = rng.uniform() * near.cutTotal;
    const std::uint32_t c = std::min<std::uint32_t>(
        static_cast<std::uint32_t>(std::upper_bound(near.cutCdf, near.cutCdf + near.cutCount, target) - near.cutCdf),
        near.cutCount - 1);
    float pdf = near.cutWeight[c] / near.cutTotal;
    std::uint32_t n = near.cutNode[c], lo = near.cutLo[c], hi = near.cutHi[c], depth = near.cutDepth[c];
    while (nodes_[n].count > kGatherBelow) {
        const std::uint32_t child = nodes_[n].child;
        const std::uint32_t mid = splitNear(near, lo, hi, depth);
        const auto [a, b] = farChildren(child, near, lo, mid, hi, sp);
        const float u = rng.uniform();
        if (!(a + b > 0.0f)) return {kNoLightSample, 0.0f};
        const float pa = a / (a + b);
        if (u < pa) {
            n = child;
            hi = mid;
            pdf *= pa;
        } else {
            n = child + 1;
            lo = mid;
            pdf *= 1.0f - pa;
        }
        ++depth;
    }
    if (nodes_[n].count > 1) {
        FarLeaves leaves;
        farLeaves(n, near, lo, hi, sp, leaves);
        if (!(leaves.total > 0.0f)) return {kNoLightSample, 0.0f};
        const std::uint32_t k = pickLeaf(leaves.importance, leaves.count, rng.uniform() * leaves.total);
        pdf *= leaves.importance[k] / leaves.total;
        n = leaves.leaf[k];
    }
    if (!(pdf > 0.0f)) return {kNoLightSample, 0.0f};
    return {nodes_[n].child, pdf};
}

float LightTree::pdfFar(const ShadingPoint& sp, const NearField& near, std::uint32_t i) const {
    if (i >= trail_.size() || near.contains(i)) return 0.0f;
    const Trail t = trail_[i];
    std::uint32_t n = 0, lo = 0, hi = near.count, k = 0;
    // Down the light's path to the cut node above it.
    const auto cutIndex = [&](std::uint32_t node) {
        return static_cast<std::uint32_t>(std::find(near.cutNode, near.cutNode + near.cutCount, node) - near.cutNode);
    };
    std::uint32_t c = cutIndex(n);
    for (; c == near.cutCount; c = cutIndex(n)) {
        if (k == t.depth) return 0.0f;  // no cut node above it: no far power there
        const std::uint32_t mid = splitNear(near, lo, hi, k);
        const bool right = (t.bits >> k) & 1u;
        n = nodes_[n].child + (right ? 1 : 0);
        if (right) lo = mid;
        else hi = mid;
        ++k;
    }
    float pdf = near.cutWeight[c] / near.cutTotal;
    for (; nodes_[n].count > kGatherBelow; ++k) {
        const std::uint32_t child = nodes_[n].child;
        const std::uint32_t mid = splitNear(near, lo, hi, k);
        const auto [a, b] = farChildren(child, near, lo, mid, hi, sp);
        if (!(a + b > 0.0f)) return 0.0f;
        const bool right = (t.bits >> k) & 1u;
        const float pa = a / (a + b);
        pdf *= right ? 1.0f - pa : pa;
        n = right ? child + 1 : child;
        if (right) lo = mid;
        else hi = mid;
    }
    if (nodes_[n].count > 1) {
        FarLeaves leaves;
        farLeaves(n, near, lo, hi, sp, leaves);
        if (!(leaves.total > 0.0f)) return 0.0f;
        for (std::uint32_t m = 0; m < leaves.count; ++m)
            if (leaves.leaf[m] == t.leaf) return pdf * (leaves.importance[m] / leaves.total);
        return 0.0f;
    }
    return pdf;
}

}  // namespace accretion
