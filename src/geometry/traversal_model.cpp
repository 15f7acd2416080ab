#include "accretion/geometry/traversal_model.h"

#include <embree3/rtcore_builder.h>

#include "accretion/core/error.h"

namespace accretion {
namespace {

/// What Embree's builder makes: inner nodes of two children and leaves of
/// one primitive, in its thread-local memory until flattened.
struct BuildNode {
    BuildNode* child[2] = {nullptr, nullptr};
    std::uint32_t prim = 0;
    bool leaf = false;
};

void* createNode(RTCThreadLocalAllocator alloc, unsigned int childCount, void*) {
    ACC_CHECK(childCount == 2);
    return new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode))) BuildNode{};
}

void setNodeChildren(void* node, void** children, unsigned int childCount, void*) {
    auto* n = static_cast<BuildNode*>(node);
    for (unsigned k = 0; k < childCount; ++k) n->child[k] = static_cast<BuildNode*>(children[k]);
}

void setNodeBounds(void*, const RTCBounds**, unsigned int, void*) {}  // the refit computes every box

void* createLeaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count, void*) {
    ACC_CHECK(count == 1);
    auto* n = new (rtcThreadLocalAlloc(alloc, sizeof(BuildNode), alignof(BuildNode))) BuildNode{};
    n->leaf = true;
    n->prim = prims[0].primID;
    return n;
}

RTCBounds merged(const RTCBounds& a, const RTCBounds& b) {
    return {std::min(a.lower_x, b.lower_x), std::min(a.lower_y, b.lower_y), std::min(a.lower_z, b.lower_z), 0.0f,
            std::max(a.upper_x, b.upper_x), std::max(a.upper_y, b.upper_y), std::max(a.upper_z, b.upper_z), 0.0f};
}

}  // namespace

void TraversalModel::build(RTCDevice device, std::span<const RTCBounds> boxes) {
    nodes_.clear();
    primitives_ = boxes.size();
    if (boxes.size() <= 1) {
        refit(boxes);
        return;
    }
    std::vector<RTCBuildPrimitive> prims(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        const RTCBounds& b = boxes[i];
        prims[i] = {b.lower_x, b.lower_y, b.lower_z, 0u, b.upper_x, b.upper_y, b.upper_z, static_cast<unsigned>(i)};
    }
    RTCBVH bvh = rtcNewBVH(device);
    RTCBuildArguments args = rtcDefaultBuildArguments();
    args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;  // SAH binning, no spatial splits
    args.maxBranchingFactor = 2;
    args.maxDepth = 64;  // traverse()'s stack holds a path's siblings
    args.minLeafSize = args.maxLeafSize = 1;
    args.bvh = bvh;
    args.primitives = prims.data();
    args.primitiveCount = args.primitiveArrayCapacity = prims.size();
    args.createNode = createNode;
    args.setNodeChildren = setNodeChildren;
    args.setNodeBounds = setNodeBounds;
    args.createLeaf = createLeaf;
    const auto* root = static_cast<const BuildNode*>(rtcBuildBVH(&args));
    ACC_CHECK(root && !root->leaf);
    // Flatten depth first, each inner node before its children.
    nodes_.reserve(boxes.size() - 1);
    std::vector<std::pair<const BuildNode*, std::int32_t*>> todo{{root, nullptr}};
    while (!todo.empty()) {
        const auto [n, link] = todo.back();
        todo.pop_back();
        if (n->leaf) {
            *link = leafOf(n->prim);
            continue;
        }
        const auto index = static_cast<std::int32_t>(nodes_.size());
        if (link) *link = index;
        nodes_.push_back({});
        // The links point into nodes_, which reserve() keeps in place.
        todo.emplace_back(n->child[1], &nodes_.back().child[1]);
        todo.emplace_back(n->child[0], &nodes_.back().child[0]);
    }
    ACC_CHECK(nodes_.size() == boxes.size() - 1);
    rtcReleaseBVH(bvh);
    refit(boxes);
}

void TraversalModel::refit(std::span<const RTCBounds> boxes) {
    ACC_CHECK(boxes.size() == primitives_);
    if (boxes.empty()) return;
    if (nodes_.empty()) {
        rootBox_ = boxes[0];
        return;
    }
    // Children come after their parent: from the last node back, each
    // child's box is final when its parent reads it.
    auto boxOf = [&](std::int32_t child) {
        if (child < 0) return boxes[primOf(child)];
        const Node& c = nodes_[std::size_t(child)];
        return merged(c.box[0], c.box[1]);
    };
    for (std::size_t k = nodes_.size(); k-- > 0;) {
        Node& n = nodes_[k];
        n.box[0] = boxOf(n.child[0]);
        n.box[1] = boxOf(n.child[1]);
    }
    rootBox_ = merged(nodes_[0].box[0], nodes_[0].box[1]);
}

}  // namespace accretion
