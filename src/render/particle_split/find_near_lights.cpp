// findNearLights: every visible particle, particle_split_passes.h's body over
// the CPU's bridge.
#include "cpu_split_bridge.h"

namespace accretion::psplit {

LightingCounters findNearLights(const CpuFrame& f) {
    const std::uint32_t n = f.texels.visible();
    PassCounters* pc = f.in.counters ? &f.in.counters->add(Pass::findNearLights, std::max(n, 1u), 1) : nullptr;
    return forEachItem(f, n, pc, [](auto& b, std::size_t v) { findNearLightsOf(b, std::uint32_t(v)); });
}

}  // namespace accretion::psplit
