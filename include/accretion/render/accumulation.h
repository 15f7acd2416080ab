#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/render/pixel_window.h"
#include "accretion/render/shard.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// How the lighting of a frame is cut into chunks. A chunk is the unit of
/// checkpointing and of sharding: for Monte Carlo estimators up to
/// kChunkSamples samples (ris: reservoirs) of every pixel, drawn from the
/// chunk's own stream, so that the image does not depend on how chunks are
/// grouped into sweeps, processes or restarts; for `exact`, kChunkRows rows.
/// Adaptive sampling (target_stderr) runs rounds of `samples` and stops a
/// pixel at the end of a round.
struct LightingPlan {
    static constexpr std::uint32_t kChunkSamples = 8;
    /// exact: one row a chunk. A chunk is what a stop request waits for: a
    /// 1080p row of disk_100k is about 15 s on 2 cores (8 rows were 2 min,
    /// past a cluster's usual grace before SIGKILL).
    static constexpr std::uint32_t kChunkRows = 1;
    /// Monte Carlo sweeps: rows per band (every remaining chunk of a band at once).
    static constexpr std::uint32_t kBandRows = 8;
    bool exact = false;
    bool adaptive = false;
    std::uint32_t samples = 0;          ///< samples per round (Monte Carlo)
    std::uint32_t chunksPerRound = 0;   ///< ceil(samples / kChunkSamples); exact: row bands
    std::uint32_t rounds = 1;           ///< adaptive: most rounds a pixel can take
    std::uint64_t begin = 0, end = 0;   ///< chunks of this run (a shard takes a part)

    std::uint64_t chunks() const { return end - begin; }
    /// Samples of chunk c (within its round).
    ACC_HD std::uint32_t chunkSamples(std::uint64_t c) const {
        if (exact) return 0;
        const std::uint32_t k = static_cast<std::uint32_t>(c % chunksPerRound);
        const std::uint32_t left = samples - k * kChunkSamples;
        return left < kChunkSamples ? left : kChunkSamples;
    }
};

/// Monte Carlo sweeps: how many pixels the next band takes. A band runs
/// every remaining chunk of its pixels at once, and a stop request or a due
/// checkpoint waits for it, so it is sized to take about `bandSeconds`:
/// from `pixelChunkSeconds`, the slowest wall time per pixel and chunk of
/// the bands so far (0 before any), over `span` chunks. The first band is a
/// probe of `groupPixels` per core (a frame at 65536 spp must not start with
/// a band of many seconds); a band grows at most 4x over `previous` (a band
/// of sky does not size one of disk); at least one group per core.
std::uint32_t nextBandPixels(double pixelChunkSeconds, std::uint64_t span, std::uint32_t previous, std::uint32_t groupPixels,
                             std::uint32_t cores, double bandSeconds);

/// The chunks of a frame for `render` at `height` rows, restricted to `shard`
/// (a contiguous range). Throws InputError when the shard cannot be cut
/// (adaptive sampling, fewer chunks than shards).
LightingPlan planLighting(const RenderSettings& render, std::uint32_t height, Shard shard = {});

/// Per-pixel running sums of the lighting estimate: everything a restart or
/// a merge needs. The estimate is sum / n, its standard error comes from
/// sumSq; `exact` stores its value with n = 1. The sums are those of the
/// window lit (render.crop's, or the whole image), row by row.
struct Accumulation {
    std::uint32_t width = 0, height = 0;  ///< the image's
    PixelWindow window;                   ///< the pixels held
    std::vector<DVec3> sum, sumSq;
    std::vector<std::uint32_t> n;         ///< samples taken
    std::vector<std::uint8_t> done;       ///< adaptive: target reached or capped
    std::vector<std::uint32_t> rejected;  ///< non-finite samples rejected (render.nonfinite)
    std::uint64_t nextChunk = 0;          ///< the RNG position: first chunk not yet added
    /// Monte Carlo sweeps run every remaining chunk of a band of pixels at
    /// once, bands in raster order over the window: rows [window.y0,
    /// bandRows) are done to the plan's end, and in row bandRows the columns
    /// [window.x0, bandCols); every other pixel is at nextChunk (image
    /// coordinates). Both 0 between frames and in a finished run.
    std::uint32_t bandRows = 0, bandCols = 0;

    /// Empty sums of `window` (the whole image when not given) of a w x h image.
    void reset(std::uint32_t w, std::uint32_t h, std::uint64_t firstChunk, const PixelWindow* window = nullptr);
    std::size_t pixels() const { return window.pixels(); }
    /// Add a disjoint part of the same work (another shard of the same window): sums, counts.
    void merge(const Accumulation& other);
};

}  // namespace accretion
