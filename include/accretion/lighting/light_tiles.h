#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/rng.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/lighting/light_sample.h"

namespace accretion {

/// RTXDI's local light presampling (Wyman and Panteleev, "Rearchitecting
/// Spatiotemporal Resampling for Production", HPG 2021): once per frame,
/// `count` tiles of `size` lights, each drawn independently in proportion
/// to power (the alias table of buildPowerTable). A pixel picks one tile
/// (the same for a block of kPixelBlock x kPixelBlock pixels, so a warp
/// reads one tile) and draws its candidates uniformly from it.
///
/// The candidate's source pdf is the power pmf of its light: every entry
/// is marginally a power sample, so a uniform pick from a tile is too, and
/// RIS with w = p_hat / p_power stays unbiased over the frame's tiles
/// (linearity: RIS needs each candidate's marginal, not independence).
/// Within one frame the tiles are a fixed draw: only the average over
/// frames or seeds is the integral, which is why `ris` (many samples of one
/// frame) refuses this source.
struct LightTiles {
    static constexpr std::uint32_t kPixelBlock = 16;  ///< RTXDI_TILE_SIZE_IN_PIXELS
    std::uint32_t count = 0;            ///< tiles
    std::uint32_t size = 0;             ///< lights per tile
    std::vector<std::uint32_t> light;   ///< count x size light indices
    std::vector<float> pdf;             ///< the power pmf of each entry's light

    bool empty() const { return light.empty(); }
    /// The tile of image pixel (x, y): one draw per pixel block and frame.
    std::uint32_t tileOf(std::uint32_t x, std::uint32_t y, std::uint32_t width, std::uint32_t frame, std::uint64_t seed) const;
    /// One candidate from tile t: a uniform entry, with its light's power pmf.
    LightSample sample(std::uint32_t t, Rng& rng) const {
        const std::size_t e = std::size_t(t) * size + rng.uniformInt(size);
        return {light[e], pdf[e]};
    }
};

/// presampleLightTiles: count x size draws from the power table, entry e
/// from its own stream (frame, seed). With counters (width size, height
/// count), each thread reads an alias entry and a light record and writes
/// its 8-byte entry (index, pdf), as RTXDI's RIS buffer stores it.
LightTiles presampleLightTiles(const AliasTable& power, std::uint32_t count, std::uint32_t size, std::uint32_t frame,
                               std::uint64_t seed, PassCounters* counters);

}  // namespace accretion
