// shadeVoxelPixels: every pixel of the frame, voxel_cache_passes.h's body
// over the CPU's bridge.
#include "cpu_voxel_bridge.h"

namespace accretion::voxel {

LightingCounters shadeVoxelPixels(const CpuFrame& f) {
    const GBuffer& gb = f.in.gbuffer;
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::shadeVoxelPixels, gb.width, gb.height) : nullptr;
    return dispatchVoxel(f, [&]<Primitive P, bool Count>() {
        auto byModel = [&]<ShadingModel SM>() {
            return forEachItem<P, Count>(f, gb.texels.size(), pc, [](auto& b, std::size_t px) { shadeVoxelPixel<SM>(b, px); });
        };
        switch (f.in.settings.shading.model) {
        case ShadingModel::lambert: return byModel.template operator()<ShadingModel::lambert>();
        case ShadingModel::sphere: return byModel.template operator()<ShadingModel::sphere>();
        case ShadingModel::isotropic: return byModel.template operator()<ShadingModel::isotropic>();
        }
        return LightingCounters{};
    });
}

}  // namespace accretion::voxel
