#pragma once
// The CPU's bridge of the voxel cache's pass bodies
// (accretion/render/voxel_cache_passes.h): the frame's cells, Embree for
// shadow rays, the thread records of counting mode. Internal to
// src/render/voxel/.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <vector>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_tree_view.h"
#include "accretion/lighting/source_pmf.h"
#include "accretion/render/visibility.h"
#include "accretion/render/voxel_cache.h"
#include "../cpu_passes.h"

namespace accretion::voxel {

/// What both CPU passes read and write.
struct CpuFrame {
    const VoxelInputs& in;
    const VoxelParams& params;
    const LightArrays& L;
    SourcePmf source;                        ///< render.source uniform or power
    LightTreeView tree;                      ///< render.source tree: the light tree, its importance without the cosine (nodes null otherwise)
    VisibilityOptions vis;
    bool shadows = true;                     ///< plan.shadowRays
    const std::vector<std::uint8_t>& occupied;
    const std::vector<VoxelCell>& cells;     ///< read
    std::vector<VoxelCell>* written = nullptr;  ///< updateVoxelCache's output
    std::vector<Vec3>* Lr = nullptr;            ///< shadeVoxelPixels' output
};

/// One cell's or pixel's bridge, with its thread record in counting mode.
template <Primitive P, bool Count>
class CpuVoxelBridge {
public:
    /// `pc`: the pass's counters in counting mode (updateVoxelCache's ray
    /// threads are among its records), else nullptr.
    CpuVoxelBridge(const CpuFrame& f, ThreadCounters* t, LightingCounters& c, PassCounters* pc = nullptr)
        : f_(f), rec_(t), c_(c), pc_(pc) {}

    const VoxelParams& params() const { return f_.params; }
    bool occupied(std::uint32_t c) {
        rec_.read(1);
        return f_.occupied[c] != 0;
    }
    /// Counting, ray r of cell c is the twin's thread of its ray launch
    /// (x = cell x * rays + r, y = the cell's row: record c * rays + r), which
    /// writes the ray for the sum; the sum (a kernel per cell) is the record
    /// of the cell's ray 0 too.
    CellRay cellRay(std::uint32_t c, std::uint32_t r) {
        if constexpr (Count) {
            CpuVoxelBridge ray(f_, &pc_->threads[std::size_t(c) * f_.params.rays + r], c_, pc_);
            const CellRay out = traceCellRay(ray, c, r);
            ray.rec_.write(sizeof(CellRay));
            rec_.read(sizeof(CellRay));
            return out;
        }
        return traceCellRay(*this, c, r);
    }
    VoxelCell cell(std::uint32_t c) {
        rec_.read(sizeof(VoxelCell));
        rec_.gather(1);
        return f_.cells[c];
    }
    void writeCell(std::uint32_t c, const VoxelCell& v) {
        rec_.write(sizeof(VoxelCell));
        (*f_.written)[c] = v;
    }
    LightSample sampleLight(const ShadingPoint& sp, PortableRng& rng) {
        rec_.trip();
        if (f_.tree.nodes) {
            const LightSample s = f_.tree.sample(sp, rng);
            if constexpr (Count) {  // a node pair per level, then the light's record
                const std::uint32_t levels = std::bit_width(std::max(1u, f_.L.count));
                rec_.gather(levels + 1);
                rec_.read(2 * levels * gpu_layout::kLightTreeNode + gpu_layout::kParticleRecord);
            }
            return s;
        }
        rec_.gather(f_.source.power ? 2 : 1);  // the alias entry, then the light's record
        rec_.read((f_.source.power ? gpu_layout::kAliasEntry : 0u) + gpu_layout::kParticleRecord);
        return f_.source.sample(rng);
    }
    bool cellTerm(const ShadingPoint& sp, std::uint32_t i, float minDist2, LightTerm& t) {
        ++c_.lightTerms;
        if (i >= f_.L.count) return false;
        const PackedLight& l = f_.L.packed[i];
        return evalLight<ShadingModel::isotropic>(sp, l.position, l.emission, std::max(l.dmin2, minDist2), t);
    }
    bool shadows() const { return f_.shadows; }
    bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) {
        const bool seen = countedShadowRay<P>(f_.in.bvh, f_.vis, f_.L, sp, i, t, c_, rec_);
        c_.shadowOccluded += !seen;
        return seen;
    }
    GBufferTexel pixel(std::size_t px) { return recordedTexel(rec_, f_.in.gbuffer.texels[px], f_.in.particles, f_.in.bvh); }
    ShadingPoint shadingPoint(const GBufferTexel& g) const { return accretion::shadingPoint(g, f_.in.particles); }
    void writePixelLr(std::size_t px, const Vec3& Lr) {
        rec_.write(gpu_layout::kRadiance);
        (*f_.Lr)[px] = Lr;
    }

private:
    const CpuFrame& f_;
    Recorder<Count> rec_;
    LightingCounters& c_;
    PassCounters* pc_;
};

/// Runs body(bridge, item) over items [0, n) on every core, each with its
/// own bridge (and, counting, the thread record `pc->threads[item x
/// threadsPerItem]`);
/// returns the threads' counters summed.
template <Primitive P, bool Count, class Body>
LightingCounters forEachItem(const CpuFrame& f, std::size_t n, PassCounters* pc, Body&& body, std::size_t threadsPerItem = 1) {
    return forEachItemParallel(n, 256, [&](std::size_t k, LightingCounters& c) {
        CpuVoxelBridge<P, Count> b(f, Count ? &pc->threads[k * threadsPerItem] : nullptr, c, pc);
        body(b, k);
    });
}

/// fn.template operator()<P, Count>() for the frame's primitive and counting mode.
template <class Fn>
LightingCounters dispatchVoxel(const CpuFrame& f, Fn&& fn) {
    return withPrimitiveAndCount(f.in.bvh.settings().primitive, f.in.counters != nullptr, fn);
}

// The passes (one file each).
LightingCounters updateVoxelCache(const CpuFrame& f);
LightingCounters shadeVoxelPixels(const CpuFrame& f);

}  // namespace accretion::voxel
