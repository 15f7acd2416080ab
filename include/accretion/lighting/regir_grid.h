#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/light_tiles.h"

namespace accretion {

/// ReGIR (Boksansky, Jukarainen and Wyman, "Rendering Many Lights with
/// Grid-Based Reservoirs", Ray Tracing Gems II, ch. 23), in RTXDI's grid
/// mode: a world-space grid of cells x cells x cells cubes, each holding
/// `lightsPerCell` reservoirs. Every slot is RIS over `buildSamples`
/// candidates from the frame's light tiles (source pdf: the power pmf),
/// resampled by the cell's target
///     p_cell(i) = luminance(I_i) / max(|p_i - c|^2, r_cell^2, dmin_i^2),
/// c the cell's centre and r_cell its half diagonal: a light's brightness
/// anywhere in the cell, positive for every emitting light.
///
/// A receiver's candidate is a uniform slot of its (jittered) cell: light y
/// with the slot's contribution weight W = w_sum / (M p_cell(y)). W is an
/// unbiased estimate of 1 / p_src(y) (E[W 1{y = i}] = 1 for every light with
/// p_cell(i) > 0, so for every light at all), and RTXDI weighs the
/// candidate by p_hat(y) W, as LightSample's pdf = 1 / W does here. A cell
/// outside the grid falls back to the light tiles (RTXDI's fallback).
struct RegirGrid {
    Vec3 origin{0.0f};            ///< the grid's lower corner
    float cellSize = 0.0f;
    std::uint32_t cells = 0;      ///< cells per axis
    std::uint32_t lightsPerCell = 0;
    std::vector<std::uint32_t> light;  ///< cells^3 x lightsPerCell slots (kNoLight: the RIS kept nothing)
    std::vector<float> W;              ///< each slot's contribution weight (0: none)

    std::uint32_t cellCount() const { return cells * cells * cells; }
    /// The cell holding p, or -1 outside the grid.
    std::int64_t cellOf(Vec3 p) const;
    Vec3 cellCentre(std::uint32_t cell) const;
    /// The cell of a receiver at p, jittered by a uniform offset of up to
    /// jitter x cellSize / 2 per axis (RTXDI's regirSamplingJitter).
    std::int64_t jitteredCell(Vec3 p, float jitter, Rng& rng) const;
    /// One candidate of cell c: a uniform slot, pdf = 1 / W (0: an empty slot).
    LightSample sample(std::uint32_t c, Rng& rng) const {
        const std::size_t s = std::size_t(c) * lightsPerCell + rng.uniformInt(lightsPerCell);
        const float w = W[s];
        return w > 0.0f ? LightSample{light[s], 1.0f / w} : LightSample{kNoLightSample, 0.0f};
    }
    /// The cell target p_cell(i) of cell c.
    float cellTarget(const LightArrays& L, std::uint32_t c, std::uint32_t i) const;
};

/// Where the grid lies: a cube of cells^3 cells centred on the lights'
/// bounding box, of cellSize each, or (cellSize = 0) just holding the box
/// (its longest side / cells). RTXDI centres its grid on the camera with a
/// cell size in scene units; a frame of an accretion disk has no camera-
/// independent scale, so the default fits the particles.
struct RegirPlacement {
    std::uint32_t cells = 16;
    float cellSize = 0.0f;
};

/// presampleRegirGrid: every slot's RIS, slot s from its own stream (frame,
/// seed); the slots of a group of 256 draw their candidates from one tile,
/// as RTXDI's coherent presampling does. With counters (width
/// lightsPerCell, height cells^3), each thread reads its candidates' tile
/// entries and light records and writes its 8-byte slot (index, W).
RegirGrid presampleRegirGrid(const LightArrays& L, const LightTiles& tiles, RegirPlacement placement,
                             std::uint32_t lightsPerCell, std::uint32_t buildSamples, std::uint32_t frame, std::uint64_t seed,
                             PassCounters* counters);

}  // namespace accretion
