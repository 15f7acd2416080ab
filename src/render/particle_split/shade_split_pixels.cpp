// shadeParticlePixels for particle_split: every pixel of the frame,
// particle_split_passes.h's body over the CPU's bridge.
#include "cpu_split_bridge.h"

namespace accretion::psplit {

LightingCounters shadeSplitPixels(const CpuFrame& f) {
    const GBuffer& gb = f.in.gbuffer;
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::shadeParticlePixels, gb.width, gb.height) : nullptr;
    return forEachItem(f, gb.texels.size(), pc, [](auto& b, std::size_t px) { interpolateSplitPixel(b, px); });
}

}  // namespace accretion::psplit
