// presampleRegirGrid: the ReGIR grid of the candidate source regir (RTXDI's
// ReGIR presampling pass), built from the frame's light tiles.
#include "restir_pass.h"

namespace accretion::restir {

/// restir.regir_cells^3 cells of restir.regir_lights_per_cell reservoirs.
RegirGrid presampleRegirGrid(const FrameContext& f) {
    const RestirSettings& r = f.rs;
    const std::uint32_t cells = r.regir_cells * r.regir_cells * r.regir_cells;
    PassCounters* pc = f.counters ? &f.counters->add(Pass::presampleRegirGrid, r.regir_lights_per_cell, cells) : nullptr;
    return accretion::presampleRegirGrid(f.L, *f.tiles, RegirPlacement{r.regir_cells, float(r.regir_cell_size)},
                                         r.regir_lights_per_cell, r.regir_build_samples, f.in.frame, f.in.settings.render.seed, pc);
}

}  // namespace accretion::restir
