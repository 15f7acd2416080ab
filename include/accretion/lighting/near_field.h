#pragma once
#include <cstdint>

namespace accretion {

/// The near field of one receiver for the `split` estimator (docs/MODEL.md
/// section 4): its k nearest lights other than its own particle, found on the
/// light tree (LightTree::nearest), whose terms are summed exactly, and the
/// receiver's own particle (i = j: no term). The far field is every other
/// light, sampled from the light tree with these lights' power taken out of
/// each node above them (LightTree::sampleFar, LightTree::pdfFar), so that
/// the far pdf is exact and sums to one over the far lights, and no draw
/// is spent on the receiver's own particle.
///
/// With them comes the far field's cut: nodes of the tree that together
/// hold every far light once (an antichain), each with a weight, its
/// importance bound at the point the field was found for (a particle's
/// centre) with the near lights' power taken out. A far draw picks a cut
/// node in proportion to its weight, then descends below it with the
/// receiver's own importances (LightTree::sampleFar): the levels above the
/// cut are paid once per field, not once per sample. The cut is refined
/// where the weight is largest (the node of largest weight is replaced by
/// its children until the size asked, at most kMaxCut), so it is fine
/// where the draws go.
/// A weight is never 0 for a node with far power (a bound without the
/// cosine is added at 1e-3), so a pixel whose normal differs from the
/// centre's still reaches every far light: the estimator stays unbiased.
///
/// The lights are kept in the tree's left-to-right order (`key`: a light's
/// path from the root, first step most significant), so that the near
/// lights below any node are one contiguous run, and `power` holds the
/// prefix sums of their powers: a node's near power is one subtraction.
struct NearField {
    static constexpr std::uint32_t kMaxNear = 1024;  ///< most nearest lights (render.near_lights)
    static constexpr std::uint32_t kMaxLights = kMaxNear + 1;
    std::uint32_t count = 0;             ///< the nearest and the receiver's own particle
    float radius2 = 0.0f;                ///< squared distance of the farthest: every far light is as far or farther
    std::uint32_t light[kMaxLights];     ///< light indices, in tree order
    std::uint64_t key[kMaxLights];       ///< their paths from the root, first step in bit 63
    double power[kMaxLights + 1];        ///< power[k]: summed luminance(I) of the first k

    static constexpr std::uint32_t kMaxCut = 1024;  ///< most nodes in the far cut
    std::uint32_t cutCount = 0;          ///< nodes in the cut (0: no far light)
    float cutTotal = 0.0f;               ///< sum of their weights
    std::uint32_t cutNode[kMaxCut];      ///< the node
    float cutWeight[kMaxCut];            ///< its weight (> 0)
    float cutCdf[kMaxCut];               ///< running sums of the weights, cutCdf[cutCount - 1] = cutTotal
    std::uint16_t cutLo[kMaxCut];        ///< its near lights: light[cutLo, cutHi)
    std::uint16_t cutHi[kMaxCut];
    std::uint8_t cutDepth[kMaxCut];      ///< its depth in the tree

    /// Whether light i is in the near field (a scan: k is small).
    bool contains(std::uint32_t i) const {
        for (std::uint32_t k = 0; k < count; ++k)
            if (light[k] == i) return true;
        return false;
    }
};

}  // namespace accretion
