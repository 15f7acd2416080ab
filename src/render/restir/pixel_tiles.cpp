// runPixelTiles: the restir passes' parallel loop over 8x8 tiles, compiled
// once for every kernel (restir_pass.h's forEachPixel).
#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "restir_pass.h"

namespace accretion::restir {

LightingCounters runPixelTiles(std::uint32_t w, std::uint32_t h,
                               const std::function<void(const PixelTile&, LightingCounters&, Scratch&)>& tile) {
    struct ThreadState {
        LightingCounters counters;
        Scratch scratch;
    };
    tbb::enumerable_thread_specific<ThreadState> state;
    tbb::parallel_for(tbb::blocked_range2d<std::uint32_t>(0, h, 8, 0, w, 8), [&](const tbb::blocked_range2d<std::uint32_t>& r) {
        ThreadState& ts = state.local();
        tile(PixelTile{r.cols().begin(), r.cols().end(), r.rows().begin(), r.rows().end()}, ts.counters, ts.scratch);
    });
    LightingCounters total;
    for (const ThreadState& ts : state) total += ts.counters;
    return total;
}

}  // namespace accretion::restir
