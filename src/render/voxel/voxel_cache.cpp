// VoxelCache: one voxel_cache frame, its two passes in the plan's order.
#include "accretion/render/voxel_cache.h"

#include "accretion/core/error.h"
#include "accretion/lighting/light_tree.h"
#include "cpu_voxel_bridge.h"

namespace accretion {

LightingCounters VoxelCache::render(const VoxelInputs& in, LightingImage& out, PassTimer& timer) {
    const FramePlan& plan = in.plan;
    ACC_CHECK(plan.voxelCache);
    ACC_CHECK((plan.sampler == LightSamplerKind::power) == (in.powerTable != nullptr));  // draws from the planned source
    ACC_CHECK((plan.sampler == LightSamplerKind::tree) == (in.lightTree != nullptr));
    const std::size_t pixels = in.gbuffer.texels.size();
    out.Lr.assign(pixels, Vec3(0.0f));
    out.Lr_stderr.assign(pixels, Vec3(0.0f));
    out.spp.assign(pixels, 0.0f);
    out.rejected.assign(pixels, 0.0f);
    for (std::size_t px = 0; px < pixels; ++px) out.spp[px] = in.gbuffer.texels[px].hit() ? 1.0f : 0.0f;

    // The grid stays where it was placed while it holds the particles.
    if (!placement_.holds(in.particles, in.origin)) {
        placement_ = placeVoxelGrid(in.particles, in.origin, vs_.cells);
        cells_.assign(placement_.cells(), voxel::VoxelCell{});
    }
    const voxel::VoxelParams params = voxelParams(in.settings, placement_, in.origin, in.camera, in.frame, in.settings.render.seed);
    const LightArrays L(in.particles, in.settings.shading);
    std::vector<voxel::VoxelCell> next(cells_.size());
    LightingCounters counters;
    {
        auto t = timer.scope(Pass::updateVoxelCache);
        const std::vector<std::uint8_t> occupied = occupiedCells(params.grid, in.particles);
        SourcePmf source{in.powerTable != nullptr, {}, L.count, L.uniformPdf};
        if (in.powerTable) source.table = in.powerTable->view();
        LightTreeView tree;
        if (in.lightTree) {
            tree = in.lightTree->view();
            tree.model = ShadingModel::isotropic;  // a cell has no normal
        }
        const voxel::CpuFrame f{in, params, L, source, tree, VisibilityOptions::from(in.settings.render), plan.shadowRays, occupied,
                                cells_, &next};
        counters += voxel::updateVoxelCache(f);
    }
    cells_.swap(next);
    {
        auto t = timer.scope(Pass::shadeVoxelPixels);
        const std::vector<std::uint8_t> none;
        const voxel::CpuFrame f{in, params, L, {}, {}, VisibilityOptions::from(in.settings.render), plan.shadowRays, none, cells_,
                                nullptr, &out.Lr};
        counters += voxel::shadeVoxelPixels(f);
    }
    return counters;
}

}  // namespace accretion
