#pragma once
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include <embree3/rtcore.h>

#include "accretion/core/math.h"

namespace accretion {

/// Where o + t d enters box b within [tnear, tfar] (tnear when it starts
/// inside), given inv = 1 / d per axis, or false when it misses: the slab
/// test, conservative at the far planes as robust ones (and GPU box tests)
/// are. The counting queries' box tests and the traversal model's.
inline bool boxEntry(const RTCBounds& b, const Vec3& o, const Vec3& inv, float tnear, float tfar, float& entry) {
    float t0 = tnear, t1 = tfar;
    const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
    for (int k = 0; k < 3; ++k) {
        float a = (lo[k] - o[k]) * inv[k], c = (hi[k] - o[k]) * inv[k];
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c * (1.0f + 6e-7f));
        if (t0 > t1) return false;
    }
    entry = t0;
    return true;
}

/// The BVH nodes a GPU's traversal visits, modelled for the cost model
/// (RayCounters::nodeVisits). Embree's own traversal cannot be counted from
/// outside, and the GPU's is not Embree's: this is a binary BVH over the
/// particles' boxes, one box a leaf, built by Embree's SAH builder
/// (rtcBuildBVH) into nodes of our own, refitted (topology kept, boxes
/// recomputed) when the GPU's BVH is refitted, and traversed as a GPU's
/// stack traversal does: the nearer child first, the farther one skipped
/// once a closer hit is found (closest hit), or stopped at the first blocker
/// found (a shadow ray). What a ray pays beyond the boxes it crosses: a ray
/// through the gaps of a dense volume enters nodes whose particles it never
/// crosses, which segment_boxes cannot see.
class TraversalModel {
public:
    /// A new topology over `boxes` (box i is primitive i).
    void build(RTCDevice device, std::span<const RTCBounds> boxes);
    /// The same topology over moved boxes (as many as built).
    void refit(std::span<const RTCBounds> boxes);
    std::size_t primitives() const { return primitives_; }
    std::size_t nodes() const { return nodes_.size(); }

    /// The inner nodes the closest-hit traversal of o + t d, t in [tnear,
    /// tfar], visits. hit(prim, tnear, tfar, t) tests a primitive whose box
    /// the ray enters: true with its t when the ray hits it in range.
    template <class Hit>
    std::uint32_t closestHit(const Vec3& o, const Vec3& d, float tnear, float tfar, Hit&& hit) const {
        return traverse<false>(o, d, tnear, tfar, hit);
    }
    /// The same for a shadow ray: the traversal stops at the first primitive
    /// hit reports (the caller's test skips the excluded ones).
    template <class Hit>
    std::uint32_t anyHit(const Vec3& o, const Vec3& d, float tnear, float tfar, Hit&& hit) const {
        return traverse<true>(o, d, tnear, tfar, hit);
    }

private:
    /// An inner node's two children (child >= 0: a node; else leaf of
    /// primitive -1 - child) and their boxes, as a GPU node holds them.
    struct Node {
        RTCBounds box[2];
        std::int32_t child[2];
    };
    static constexpr std::int32_t leafOf(std::uint32_t prim) { return -1 - std::int32_t(prim); }
    static constexpr std::uint32_t primOf(std::int32_t leaf) { return std::uint32_t(-1 - leaf); }

    template <bool AnyHit, class Hit>
    std::uint32_t traverse(const Vec3& o, const Vec3& d, float tnear, float tfar, Hit& hit) const {
        if (primitives_ == 0) return 0;
        const Vec3 inv(1.0f / d.x, 1.0f / d.y, 1.0f / d.z);
        float entry;
        if (nodes_.empty()) {  // one primitive: the root is its leaf
            if (boxEntry(rootBox_, o, inv, tnear, tfar, entry)) hit(0u, tnear, tfar, entry);
            return 0;
        }
        if (!boxEntry(rootBox_, o, inv, tnear, tfar, entry)) return 0;
        struct Entry {
            std::int32_t child;
            float t;
        };
        Entry stack[128];
        int top = 0;
        stack[top++] = {0, entry};
        std::uint32_t visits = 0;
        while (top > 0) {
            const Entry e = stack[--top];
            if (e.t > tfar) continue;  // a closer hit was found since it was pushed
            if (e.child < 0) {
                float t;
                if (hit(primOf(e.child), tnear, tfar, t)) {
                    if constexpr (AnyHit) return visits;
                    tfar = t;
                }
                continue;
            }
            ++visits;
            const Node& n = nodes_[std::size_t(e.child)];
            float t0, t1;
            const bool in0 = boxEntry(n.box[0], o, inv, tnear, tfar, t0);
            const bool in1 = boxEntry(n.box[1], o, inv, tnear, tfar, t1);
            if (in0 && in1) {  // the farther first on the stack, the nearer popped next
                const bool firstNear = t0 <= t1;
                stack[top++] = firstNear ? Entry{n.child[1], t1} : Entry{n.child[0], t0};
                stack[top++] = firstNear ? Entry{n.child[0], t0} : Entry{n.child[1], t1};
            } else if (in0) {
                stack[top++] = {n.child[0], t0};
            } else if (in1) {
                stack[top++] = {n.child[1], t1};
            }
        }
        return visits;
    }

    std::vector<Node> nodes_;  ///< depth first: a node's children after it
    RTCBounds rootBox_{};
    std::size_t primitives_ = 0;
};

}  // namespace accretion
