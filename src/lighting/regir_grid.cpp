#include "accretion/lighting/regir_grid.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/reservoir.h"

namespace accretion {

std::int64_t RegirGrid::cellOf(Vec3 p) const {
    const Vec3 g = (p - origin) / cellSize;
    if (!(g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f)) return -1;  // NaN too
    const auto ix = std::uint32_t(g.x), iy = std::uint32_t(g.y), iz = std::uint32_t(g.z);
    if (!(g.x < float(cells) && g.y < float(cells) && g.z < float(cells)) || ix >= cells || iy >= cells || iz >= cells) return -1;
    return (std::int64_t(iz) * cells + iy) * cells + ix;
}

Vec3 RegirGrid::cellCentre(std::uint32_t c) const {
    const std::uint32_t ix = c % cells, iy = (c / cells) % cells, iz = c / (cells * cells);
    return origin + (Vec3(float(ix), float(iy), float(iz)) + 0.5f) * cellSize;
}

std::int64_t RegirGrid::jitteredCell(Vec3 p, float jitter, Rng& rng) const {
    const float a = jitter * cellSize;
    const float ux = rng.uniform(), uy = rng.uniform(), uz = rng.uniform();
    return cellOf(p + a * (Vec3(ux, uy, uz) - 0.5f));
}

float RegirGrid::cellTarget(const LightArrays& L, std::uint32_t c, std::uint32_t i) const {
    const PackedLight& l = L.packed[i];
    const Vec3 d = l.position - cellCentre(c);
    const float rCell2 = 0.75f * cellSize * cellSize;  // (sqrt(3) / 2 cellSize)^2
    return luminance(l.emission) / std::max({glm::dot(d, d), rCell2, l.dmin2});
}

RegirGrid presampleRegirGrid(const LightArrays& L, const LightTiles& tiles, RegirPlacement placement,
                             std::uint32_t lightsPerCell, std::uint32_t buildSamples, std::uint32_t frame, std::uint64_t seed,
                             PassCounters* counters) {
    RegirGrid g;
    g.cells = placement.cells;
    g.lightsPerCell = lightsPerCell;
    Vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::uint32_t i = 0; i < L.count; ++i) {
        lo = glm::min(lo, L.packed[i].position);
        hi = glm::max(hi, L.packed[i].position);
    }
    if (L.count == 0) lo = hi = Vec3(0.0f);
    const Vec3 extent = hi - lo;
    // Fitted: the box's longest side, with a margin so that its far faces
    // fall inside the last cells.
    g.cellSize = placement.cellSize > 0.0f ? placement.cellSize
                                           : std::max(1e-6f, 1.0001f * std::max({extent.x, extent.y, extent.z}) / float(g.cells));
    g.origin = 0.5f * (lo + hi) - 0.5f * float(g.cells) * g.cellSize;

    const std::size_t slots = std::size_t(g.cellCount()) * lightsPerCell;
    g.light.assign(slots, kNoLight);
    g.W.assign(slots, 0.0f);
    constexpr std::size_t kGroup = 256;  // slots that presample from one tile
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slots, kGroup), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
            const auto cell = static_cast<std::uint32_t>(s / lightsPerCell);
            Rng group(s / kGroup, frame, RngPass::presampleRegir, seed, 1);
            const std::uint32_t tile = group.uniformInt(tiles.count);
            Rng rng(s, frame, RngPass::presampleRegir, seed);
            Reservoir res;
            for (std::uint32_t k = 0; k < buildSamples; ++k) {
                const LightSample x = tiles.sample(tile, rng);
                const float target = g.cellTarget(L, cell, x.i);
                res.update(x.i, target / x.pdf, target, rng.uniform());
            }
            res.finalize();
            if (res.W > 0.0f && std::isfinite(res.W)) {
                g.light[s] = res.y;
                g.W[s] = res.W;
            }
            if (counters) {
                Recorder<true> rec(&counters->threads[s]);
                rec.trip(buildSamples);
                rec.read(buildSamples * (gpu_layout::kRisEntry + gpu_layout::kParticleRecord));
                rec.gather(2 * buildSamples);
                rec.write(gpu_layout::kRisEntry);
            }
        }
    });
    return g;
}

}  // namespace accretion
