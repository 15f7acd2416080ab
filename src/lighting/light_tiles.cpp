#include "accretion/lighting/light_tiles.h"

#include <tbb/parallel_for.h>

#include "accretion/counters/gpu_layouts.h"

namespace accretion {

std::uint32_t LightTiles::tileOf(std::uint32_t x, std::uint32_t y, std::uint32_t width, std::uint32_t frame,
                                 std::uint64_t seed) const {
    const std::uint32_t blocksPerRow = (width + kPixelBlock - 1) / kPixelBlock;
    const std::uint64_t block = std::uint64_t(y / kPixelBlock) * blocksPerRow + x / kPixelBlock;
    Rng rng(block, frame, RngPass::tileSelection, seed);
    return rng.uniformInt(count);
}

LightTiles presampleLightTiles(const AliasTable& power, std::uint32_t count, std::uint32_t size, std::uint32_t frame,
                               std::uint64_t seed, PassCounters* counters) {
    LightTiles t;
    t.count = count;
    t.size = size;
    const std::size_t n = std::size_t(count) * size;
    t.light.resize(n);
    t.pdf.resize(n);
    const std::uint32_t lights = power.size();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t e = r.begin(); e != r.end(); ++e) {
            Rng rng(e, frame, RngPass::presampleTiles, seed);
            const std::uint32_t bucket = rng.uniformInt(lights);
            const std::uint32_t i = power.sample(bucket, rng.uniform());
            t.light[e] = i;
            t.pdf[e] = power.pmf(i);
            if (counters) {
                Recorder<true> rec(&counters->threads[e]);
                rec.trip();
                rec.read(gpu_layout::kAliasEntry + gpu_layout::kParticleRecord);
                rec.gather(2);
                rec.write(gpu_layout::kRisEntry);
            }
        }
    });
    return t;
}

}  // namespace accretion
