#pragma once
// The twin's bridge of the voxel cache's pass bodies
// (accretion/render/voxel_cache_passes.h): the launch's cells, its light
// source, OptiX shadow rays (Visibility: sp, light, term -> seen, counted by
// the raygen), nothing else counted.
#include "accretion/render/voxel_cache_passes.h"
#include "launch_params.h"
#include "restir_device.h"

namespace accretion::twin {

/// The visibility of a pass that traces no shadow ray (shadeVoxelPixels).
struct NoVoxelRays {
    __device__ bool operator()(const ShadingPoint&, std::uint32_t, const LightTerm&) const { return true; }
};

template <class Visibility = NoVoxelRays>
class VoxelBridge {
public:
    __device__ VoxelBridge(const LaunchParams& p, Visibility visibility = {}, LaunchCounters* counters = nullptr)
        : p_(p), visibility_(visibility), counters_(counters) {}

    __device__ const voxel::VoxelParams& params() const { return p_.voxel.params; }
    __device__ bool occupied(std::uint32_t c) const { return p_.voxel.occupied[c] != 0; }
    /// The ray the launch of traceCellRays traced (updateVoxelCell sums them).
    __device__ voxel::CellRay cellRay(std::uint32_t c, std::uint32_t r) const {
        return p_.voxel.rays[std::size_t(c) * p_.voxel.params.rays + r];
    }
    __device__ voxel::VoxelCell cell(std::uint32_t c) const { return p_.voxel.read[c]; }
    __device__ void writeCell(std::uint32_t c, const voxel::VoxelCell& v) const { p_.voxel.write[c] = v; }
    /// render.source at a cell's point: the light tree without the cosine
    /// (the CPU's VoxelCache sets the view's model isotropic too), else the
    /// source pmf.
    __device__ LightSample sampleLight(const ShadingPoint& sp, PortableRng& rng) const {
        if (p_.tree.nodes) {
            LightTreeView tree = p_.tree;
            tree.model = ShadingModel::isotropic;
            return tree.sample(sp, rng);
        }
        return p_.source.sample(rng);
    }
    __device__ bool cellTerm(const ShadingPoint& sp, std::uint32_t i, float minDist2, LightTerm& t) const {
        if (counters_) ++counters_->lightTerms;
        const LightView& L = p_.lights;
        if (i >= L.count) return false;
        return evalLight<ShadingModel::isotropic>(sp, L.position[i], L.emission[i], fmaxf(L.dmin2[i], minDist2), t);
    }
    __device__ bool shadows() const { return p_.shadows; }
    __device__ bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) const { return visibility_(sp, i, t); }
    __device__ GBufferTexel pixel(std::size_t px) const { return p_.gbuffer[px]; }
    __device__ ShadingPoint shadingPoint(const GBufferTexel& g) const { return shadingPointOf(g, p_.lights); }
    __device__ void writePixelLr(std::size_t px, const Vec3& Lr) const { p_.Lr[px] = Lr; }

private:
    const LaunchParams& p_;
    Visibility visibility_;
    LaunchCounters* counters_;
};

}  // namespace accretion::twin
