// presampleLightTiles: the light tiles of the candidate sources tiles and
// regir (RTXDI's local light presampling pass).
#include "restir_pass.h"

namespace accretion::restir {

/// restir.tile_count tiles of restir.tile_size lights by power.
LightTiles presampleLightTiles(const FrameContext& f) {
    const RestirSettings& r = f.rs;
    PassCounters* pc = f.counters ? &f.counters->add(Pass::presampleLightTiles, r.tile_size, r.tile_count) : nullptr;
    return accretion::presampleLightTiles(*f.in.powerTable, r.tile_count, r.tile_size, f.in.frame, f.in.settings.render.seed, pc);
}

}  // namespace accretion::restir
