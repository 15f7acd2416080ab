#pragma once
// The CPU's bridge of particle_split's pass bodies
// (accretion/render/particle_split_passes.h): the frame's texels and near
// lights, Embree for shadow rays, the thread records of counting mode.
// Internal to src/render/particle_split/.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/render/particle_split.h"
#include "accretion/render/particle_split_passes.h"
#include "accretion/render/particle_texel_grid.h"
#include "accretion/render/visibility.h"
#include "../cpu_passes.h"

namespace accretion::psplit {

/// What the CPU passes read and write.
struct CpuFrame {
    const ParticleSplitInputs& in;
    const SplitParams& params;
    const LightArrays& L;
    LightTreeView tree;
    const std::vector<std::uint64_t>& paths;       ///< each light's path in the tree (LightTree::paths)
    VisibilityOptions vis;
    bool shadows = true;                           ///< plan.shadowRays
    const ParticleTexels& texels;
    std::vector<std::uint32_t>& near;              ///< slot v's near lights at v x params.nearCount (kNoNearLight past its count)
    std::vector<std::uint32_t>& nearFound;         ///< how many each slot has
    std::vector<float>& nearRadius2;               ///< the farthest one's squared distance
    const std::vector<std::uint32_t>& prevSlotOf;  ///< history: last frame's slots (empty: none)
    const std::vector<std::uint32_t>& prevNear;    ///< far_handoff: last frame's near lights by its slots (as near)
    const std::vector<std::uint32_t>& prevNearFound;
    const std::vector<Vec3>& prevTexelLr;
    std::vector<Vec3>& texelLr;
    const std::vector<Vec3>& prevTexelFar;         ///< history_of far: last frame's far means' average (else empty)
    std::vector<Vec3>& texelFar;
    const std::vector<std::uint32_t>& prevTexelAge;  ///< history_start mean: last frame's texels' ages (else empty)
    std::vector<std::uint32_t>& texelAge;
    const std::vector<Vec3>& prevTexelNear;        ///< far_handoff: last frame's texels' near terms, texel q's m at q x nearCount + m
    std::vector<Vec3>& texelNear;
    std::vector<std::uint32_t>& texelRejected;     ///< non-finite far draws per texel
    std::vector<std::uint32_t>& newIndex;          ///< far_new: each texel's place among those without history (kNoSlot: it has one)
    std::vector<Vec3>& Lr;                         ///< the pixels'
};

/// One item's bridge (a slot, a texel or a pixel), with its thread record in counting mode.
template <ShadingModel SM, Primitive P, bool Count>
class CpuSplitBridge {
public:
    /// `pc`: the pass's counters in counting mode (shadeSplitTexels' ray
    /// threads are its records splitRayThread(q, r)), else nullptr.
    CpuSplitBridge(const CpuFrame& f, ThreadCounters* t, LightingCounters& c, PassCounters* pc = nullptr)
        : f_(f), rec_(t), c_(c), pc_(pc) {}

    const SplitParams& params() const { return f_.params; }

    // findNearLights
    std::uint32_t particleOfSlot(std::uint32_t v) {
        rec_.read(4 + gpu_layout::kParticleRecord);
        return f_.texels.particleOf[v];
    }
    Vec3 particlePosition(std::uint32_t j) const { return f_.in.particles.position[j]; }
    std::uint64_t lightPath(std::uint32_t j) const { return f_.paths[j]; }
    const LightTreeView& tree() const { return f_.tree; }
    void writeNear(std::uint32_t v, const std::uint32_t* light, std::uint32_t count, float radius2) {
        if constexpr (Count) countNearSearch(v);
        rec_.write(4 * (count + 2));
        const std::size_t base = std::size_t(v) * f_.params.nearCount;
        std::copy(light, light + count, f_.near.begin() + base);
        std::fill(f_.near.begin() + base + count, f_.near.begin() + base + f_.params.nearCount, kNoNearLight);
        f_.nearFound[v] = count;
        f_.nearRadius2[v] = radius2;
    }

    // shadeSplitTexels
    GBufferTexel texel(std::size_t q) { return recordedTexel(rec_, f_.texels.grid.texels[q], f_.in.particles, f_.in.bvh); }
    ShadingPoint shadingPoint(const GBufferTexel& g) const { return accretion::shadingPoint(g, f_.in.particles); }
    std::uint32_t nearLight(std::uint32_t v, std::uint32_t m) {
        rec_.read(4);
        return f_.near[std::size_t(v) * f_.params.nearCount + m];
    }
    std::uint32_t nearLights(std::uint32_t v, std::uint32_t* light) {
        const std::uint32_t n = f_.nearFound[v];
        rec_.read(4 * (n + 2));
        std::copy_n(f_.near.begin() + std::size_t(v) * f_.params.nearCount, n, light);
        return n;
    }
    float nearRadius2(std::uint32_t v) const { return f_.nearRadius2[v]; }
    /// Counting, ray r of texel q is the twin's thread splitRayThread(q, r)
    /// of its ray launch, which writes the ray for the sum; the sum (a
    /// kernel per texel) is record q's too, as its dispatch is the pass's second.
    SplitRay splitRay(std::size_t q, std::uint32_t r) {
        if constexpr (Count) {
            const std::size_t newIndex = r >= raysPerTexel(f_.params) ? f_.newIndex[q] : 0;
            CpuSplitBridge ray(f_, &pc_->threads[splitRayThread(f_.params, f_.texels.grid.texels.size(), q, r, newIndex)], c_, pc_);
            const SplitRay out = traceSplitRay(ray, q, r);
            ray.rec_.write(sizeof(SplitRay));
            rec_.read(sizeof(SplitRay));
            return out;
        }
        return traceSplitRay(*this, q, r);
    }
    LightSample sampleFar(const ShadingPoint& sp, PortableRng& rng, const FarImportance& importance) {
        rec_.trip();
        if constexpr (Count) {  // a node pair per level
            const std::uint32_t levels = std::bit_width(std::max(1u, f_.L.count));
            rec_.gather(levels);
            rec_.read(2 * levels * gpu_layout::kLightTreeNode);
        }
        return f_.tree.sample(sp, rng, importance);
    }
    bool term(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) {
        ++c_.lightTerms;
        rec_.read(gpu_layout::kParticleRecord);
        rec_.gather(1);
        if (i >= f_.L.count) return false;
        const PackedLight& l = f_.L.packed[i];
        return evalLight<SM>(sp, l.position, l.emission, l.dmin2, t);
    }
    bool shadows() const { return f_.shadows; }
    bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) {
        const bool seen = countedShadowRay<P>(f_.in.bvh, f_.vis, f_.L, sp, i, t, c_, rec_);
        c_.shadowOccluded += !seen;
        return seen;
    }
    void reject(std::size_t q) {
        ++f_.texelRejected[q];
        ++c_.nonFinite;
    }
    bool historyTexelOf(std::uint32_t j, std::uint32_t sub, std::size_t& q) {
        rec_.read(4);
        rec_.gather(1);
        if (j >= f_.prevSlotOf.size() || f_.prevSlotOf[j] == kNoSlot) return false;
        q = std::size_t(f_.prevSlotOf[j]) * f_.params.texelsPerParticle() + sub;
        return true;
    }
    std::uint32_t historyNearLights(std::uint32_t v, std::uint32_t* light) {
        const std::uint32_t n = f_.prevNearFound[v];
        rec_.read(4 * (n + 1));
        std::copy_n(f_.prevNear.begin() + std::size_t(v) * f_.params.nearCount, n, light);
        return n;
    }
    Vec3 historyNearValue(std::size_t q, std::uint32_t m) {
        rec_.read(gpu_layout::kRadiance);
        return f_.prevTexelNear[q * f_.params.nearCount + m];
    }
    void writeTexelNear(std::size_t q, std::uint32_t m, const Vec3& v) {
        rec_.write(gpu_layout::kRadiance);
        f_.texelNear[q * f_.params.nearCount + m] = v;
    }
    Vec3 historyLr(std::size_t q) {
        rec_.read(gpu_layout::kRadiance);
        return f_.prevTexelLr[q];
    }
    void writeTexelLr(std::size_t q, const Vec3& Lr) {
        rec_.write(gpu_layout::kRadiance);
        f_.texelLr[q] = Lr;
    }
    Vec3 historyFar(std::size_t q) {
        rec_.read(gpu_layout::kRadiance);
        return f_.prevTexelFar[q];
    }
    void writeTexelFar(std::size_t q, const Vec3& far) {
        rec_.write(gpu_layout::kRadiance);
        f_.texelFar[q] = far;
    }
    std::uint32_t historyAge(std::size_t q) {
        rec_.read(4);
        return f_.prevTexelAge[q];
    }
    void writeTexelAge(std::size_t q, std::uint32_t n) {
        rec_.write(4);
        f_.texelAge[q] = n;
    }

    // shadeParticlePixels
    GBufferTexel pixel(std::size_t px) { return recordedTexel(rec_, f_.in.gbuffer.texels[px], f_.in.particles, f_.in.bvh); }
    std::uint32_t slotOf(std::uint32_t j) {
        rec_.read(4);
        rec_.gather(1);
        return f_.texels.slotOf[j];
    }
    Vec2 pixelUv(const GBufferTexel& g) const {
        return billboardUv(g.local, f_.in.particles.radius[g.particle], f_.in.bvh.frame(g.particle));
    }
    Vec3 texelLr(std::size_t q) {
        rec_.read(gpu_layout::kRadiance);
        return f_.texelLr[q];
    }
    void writePixelLr(std::size_t px, const Vec3& Lr) {
        rec_.write(gpu_layout::kRadiance);
        f_.Lr[px] = Lr;
    }

private:
    /// Counting, slot v's near search as it ran: the same search again,
    /// each step a trip (a loop iteration, lanes diverging on their
    /// search's length); a node read is a dependent read of the node and,
    /// for an inner node, of its two children's bounds; a swap of the heap
    /// of the k best is in the thread's own (local) memory.
    void countNearSearch(std::uint32_t v) {
        const std::uint32_t j = f_.texels.particleOf[v];
        std::uint32_t light[kMaxNear];
        float d2[kMaxNear];
        nearestLights(f_.tree, particlePosition(j), j, lightPath(j), f_.params.nearCount, light, d2, [this](SearchStep step) {
            rec_.trip();
            if (step == SearchStep::sift) return;
            const bool leaf = step == SearchStep::leaf;
            rec_.gather(leaf ? 1 : 2);
            rec_.read((leaf ? 1 : 3) * gpu_layout::kLightTreeNode);
        });
    }

    const CpuFrame& f_;
    Recorder<Count> rec_;
    LightingCounters& c_;
    PassCounters* pc_;
};

/// Runs body(bridge, item) over items [0, n) on every core, each with its
/// own bridge (and, counting, the thread record `pc->threads[item]`), for
/// the frame's shading model, primitive and counting mode; returns the
/// threads' counters summed.
template <class Body>
LightingCounters forEachItem(const CpuFrame& f, std::size_t n, PassCounters* pc, Body&& body) {
    return withShadingModel(f.in.settings.shading.model, [&]<ShadingModel SM>() {
        return withPrimitiveAndCount(f.in.bvh.settings().primitive, pc != nullptr, [&]<Primitive P, bool Count>() {
            return forEachItemParallel(n, 64, [&](std::size_t k, LightingCounters& c) {
                CpuSplitBridge<SM, P, Count> b(f, Count ? &pc->threads[k] : nullptr, c, pc);
                body(b, k);
            });
        });
    });
}

}  // namespace accretion::psplit

namespace accretion::psplit {

// The passes (one file each).
LightingCounters findNearLights(const CpuFrame& f);
LightingCounters shadeSplitTexels(const CpuFrame& f);
LightingCounters shadeSplitPixels(const CpuFrame& f);

}  // namespace accretion::psplit
