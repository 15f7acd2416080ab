// shadeVoxelPixels: every pixel of the frame, voxel_cache_passes.h's body
// over the CPU's bridge.
#include "cpu_voxel_bridge.h"

namespace accretion::voxel {

LightingCounters shadeVoxelPixels(const CpuFrame& f) {
    const GBuffer& gb = f.in.gbuffer;
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::shadeVoxelPixels, gb.width, gb.height) : nullptr;
    return dispatchVoxel(f, [&]<Primitive P, bool Count>() {
        return withShadingModel(f.in.settings.shading.model, [&]<ShadingModel SM>() {
            return forEachItem<P, Count>(f, gb.texels.size(), pc, [](auto& b, std::size_t px) { shadeVoxelPixel<SM>(b, px); });
        });
    });
}

}  // namespace accretion::voxel
