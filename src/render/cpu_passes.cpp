// runItemRanges: the item passes' parallel loop, compiled once for every
// kernel (cpu_passes.h's forEachItemParallel).
#include "cpu_passes.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

namespace accretion {

LightingCounters runItemRanges(std::size_t n, std::size_t grain,
                               const std::function<void(std::size_t, std::size_t, LightingCounters&)>& range) {
    tbb::enumerable_thread_specific<LightingCounters> counters;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
        range(r.begin(), r.end(), counters.local());
    });
    LightingCounters total;
    for (const LightingCounters& c : counters) total += c;
    return total;
}

}  // namespace accretion
