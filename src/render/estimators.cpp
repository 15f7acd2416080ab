#include "accretion/render/estimators.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <ranges>
#include <span>

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "accretion/core/error.h"
#include "accretion/core/rng.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/lighting/near_field.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/render/sample_sums.h"
#include "accretion/render/visibility.h"
#include "light_loops.h"

namespace accretion {
using namespace light_loops;

namespace {

/// ris (docs/MODEL.md section 4): per sample, one reservoir streams M candidates
/// from the source pmf with w = p_hat / p_src, p_hat = luminance(f I G)
/// without visibility; the kept y gets one shadow ray, weighted by W. A
/// non-finite candidate weight is rejected (zero_sample: the candidate gets
/// weight 0; discard: the reservoir is dropped).
template <ShadingModel M, Primitive P, LightSource S, bool Traced = false>
void risChunk(const ParticleBvh& bvh, const LightArrays& L, const AliasTable* table, const LightTree* tree,
              const ShadingPoint& sp, std::uint32_t count, std::uint32_t candidates, const VisibilityOptions& vis, bool shadows,
              Rng& rng, PixelSums& acc, RayCounters* rc) {
    LightingCounters& c = acc.c;
    const CandidateSampler<S> source{L, table, tree};
    for (std::uint32_t k = 0; k < count; ++k) {
        Reservoir r;
        LightTerm t_y{};
        bool discarded = false;
        for (std::uint32_t m = 0; m < candidates; ++m) {
            const LightSample x = source.sample(sp, rng);
            LightTerm t{};
            float p_hat = 0.0f;
            ++c.lightTerms;
            if (L.term<M>(sp, x.i, t)) p_hat = luminance(t.value);
            float w = x.pdf > 0.0f ? p_hat / x.pdf : 0.0f;  // the tree drew no light: a zero candidate
            if (!std::isfinite(w) || !std::isfinite(p_hat)) {
                discarded = acc.reject() || discarded;
                w = p_hat = 0.0f;
            }
            if (r.update(x.i, w, p_hat, rng.uniform())) t_y = t;
            if constexpr (Traced) {
                if (m == 0) acc.trace->reservoirs.emplace_back();
                acc.trace->reservoirs.back().candidates.push_back({x.i, x.pdf, p_hat, w});
            }
        }
        if (discarded) continue;
        r.finalize();
        PixelTrace::RisReservoir* traced = Traced ? &acc.trace->reservoirs.back() : nullptr;
        if (traced) traced->reservoir = r;
        if (r.W <= 0.0f) {
            acc.addZero();
            continue;
        }
        const bool v = seen<P>(bvh, L, sp, r.y, t_y, vis, shadows, c, rc);
        if (v) acc.add(DVec3(t_y.value) * double(r.W));
        else acc.addZero();
        if (traced) {
            traced->visible = v;
            traced->estimate = v ? Vec3(DVec3(t_y.value) * double(r.W)) : Vec3(0.0f);
        }
    }
}

/// One hit pixel of a group while its chunks run.
struct GroupPixel {
    std::size_t px = 0;     ///< y * width + x in the whole image: its streams, its trace
    std::size_t slot = 0;   ///< in the window's buffers (G-buffer, sums, image)
    ShadingPoint sp;
    PixelSums sums;
    RayCounters rays;       ///< counting mode: its shadow rays' traversal
    LightSample xs[LightingPlan::kChunkSamples];  ///< a chunk's lights (chunkSamples() <= kChunkSamples)
    const NearField* field = nullptr;  ///< split: the near lights of its particle (NearFieldCache)
    DVec3 near{0.0};                   ///< split: their exact sum at this pixel's point
};

/// Pixels shaded together: up to this many of a tile row.
constexpr std::uint32_t kGroupPixels = 8;

/// One chunk of every active pixel of a group. uniform / power / tree draw
/// the lights of every pixel first (their records prefetched), then shade
/// them, so that the random reads of eight pixels overlap; each pixel's
/// stream, samples and sums are those it has alone.
template <ShadingModel M, Primitive P, bool Count, EstimatorKind K>
void runChunk(const LightingInputs& in, const LightArrays& L, const VisibilityOptions& vis, bool shadows,
              std::uint64_t chunk, std::uint32_t count, GroupPixel* pix, std::uint32_t n) {
    const auto stream = [&](const GroupPixel& p) {
        return Rng(p.px, in.frame, RngPass::lightSampling, in.render.seed, chunk + 1);
    };
    if constexpr (estimatorInfo(K).resampling) {
        // The candidates' source: the plan built the power table or the light tree for it.
        const auto chunk = [&]<LightSource S>(GroupPixel& p, Rng& rng, RayCounters* rc) {
            if (p.sums.trace) [[unlikely]]  // render --pixel
                risChunk<M, P, S, true>(in.bvh, L, in.powerTable, in.lightTree, p.sp, count, in.render.candidates, vis, shadows, rng, p.sums, rc);
            else
                risChunk<M, P, S>(in.bvh, L, in.powerTable, in.lightTree, p.sp, count, in.render.candidates, vis, shadows, rng, p.sums, rc);
        };
        for (std::uint32_t k = 0; k < n; ++k) {
            GroupPixel& p = pix[k];
            if (p.sums.done) continue;
            Rng rng = stream(p);
            RayCounters* rc = Count ? &p.rays : nullptr;
            withLightSource(in.render.source, [&]<LightSource S>() {
                // restir's presampled sources: refused for ris by the scene's validation
                if constexpr (!sourceInfo(S).presampled) chunk.template operator()<S>(p, rng, rc);
            });
        }
    } else {
        for (std::uint32_t k = 0; k < n; ++k) {
            if (pix[k].sums.done) continue;
            Rng rng = stream(pix[k]);
            drawLights<K>(in, L, pix[k].sp, pix[k].field, rng, count, pix[k].xs);
        }
        for (std::uint32_t k = 0; k < n; ++k) {
            GroupPixel& p = pix[k];
            if (p.sums.done) continue;
            if (p.sums.trace) [[unlikely]]  // render --pixel
                shadeSamples<M, P, true>(in.bvh, L, p.sp, p.xs, count, p.near, vis, shadows, p.sums, Count ? &p.rays : nullptr);
            else
                shadeSamples<M, P>(in.bvh, L, p.sp, p.xs, count, p.near, vis, shadows, p.sums, Count ? &p.rays : nullptr);
        }
    }
}

/// Chunks [c0, c1) of one group's hit pixels; adaptive sampling stops a
/// pixel at the end of a round.
template <ShadingModel M, Primitive P, bool Count, EstimatorKind K>
void runChunks(const LightingInputs& in, const LightArrays& L, const LightingPlan& plan, const VisibilityOptions& vis,
               bool shadows, std::uint64_t c0, std::uint64_t c1, GroupPixel* pix, std::uint32_t n) {
    for (std::uint64_t chunk = c0; chunk < c1; ++chunk) {
        runChunk<M, P, Count, K>(in, L, vis, shadows, chunk, plan.chunkSamples(chunk), pix, n);
        bool active = false;
        for (std::uint32_t k = 0; k < n; ++k) {
            PixelSums& s = pix[k].sums;
            if (!s.done && plan.adaptive && (chunk + 1) % plan.chunksPerRound == 0)
                s.done = roundDone(s.sum, s.sumSq, s.n, static_cast<std::uint32_t>((chunk + 1) / plan.chunksPerRound), in.render.samples,
                                   in.render.max_samples, in.render.target_stderr);
            active = active || !s.done;
        }
        if (!active) return;
    }
}

/// split: the near fields of one thread's recent particles. A near field is
/// the k lights nearest to a particle's centre (not to the pixel's point on
/// it), so every pixel of a particle shares one search: at 1080p a particle
/// of disk_100k covers several pixels of a tile. What a pixel gets depends
/// on its particle alone, never on the cache, the tiles or the threads.
/// Direct-mapped; a particle whose slot an earlier pixel of the same group
/// still uses gets the group's spare field instead.
struct NearFieldCache {
    static constexpr std::uint32_t kSlots = 64;
    std::uint32_t particle[kSlots];
    Vec3 normal[kSlots];
    NearField field[kSlots];
    NearField spare[kGroupPixels];
    NearFieldCache() { std::fill(std::begin(particle), std::end(particle), kNoParticle); }
};

/// The near field of particle j (a pixel on it has normal n), from the cache or found.
const NearField& nearFieldOf(const LightingInputs& in, std::uint32_t j, const Vec3& n, NearFieldCache& cache,
                             std::uint64_t& pinned, std::uint32_t& spares) {
    static_assert(NearFieldCache::kSlots == 64);
    const std::uint32_t s = (j * 0x9e3779b1u) >> 26;  // Fibonacci hashing onto 64 slots
    const std::uint64_t bit = std::uint64_t(1) << s;
    if (cache.particle[s] == j) {
        // What a pixel gets must not depend on which pixel of j came first.
        ACC_CHECK(in.shading.model != ShadingModel::lambert || cache.normal[s] == n);
        pinned |= bit;
        return cache.field[s];
    }
    NearField* out = &cache.spare[spares];
    if (pinned & bit) {
        ++spares;  // at most one per pixel of the group
    } else {
        out = &cache.field[s];
        cache.particle[s] = j;
        cache.normal[s] = n;
        pinned |= bit;
    }
    nearestToParticle(in, j, nearLightCount(in.render, in.nearLights), n, farCutSize(in.render), *out);
    return *out;
}

/// split: a pixel's near field (its particle's, from the cache) and the
/// exact sum of its terms at the pixel's point, once per pixel per sweep;
/// a sweep runs all of a pixel's remaining chunks (run(): a band of pixels
/// at a time), so nothing is kept between sweeps and k is bounded by
/// NearField::kMaxNear alone, whatever the resolution.
template <ShadingModel M, Primitive P, bool Count>
void prepareNearField(const LightingInputs& in, const LightArrays& L, const VisibilityOptions& vis, bool shadows,
                      GroupPixel& p, NearFieldCache& cache, std::uint64_t& pinned, std::uint32_t& spares) {
    p.field = &nearFieldOf(in, p.sp.self, p.sp.n, cache, pinned, spares);
    const std::span<const std::uint32_t> lights(p.field->light, p.field->count);
    RayCounters* rc = Count ? &p.rays : nullptr;
    p.near = p.sums.trace ? sumTerms<M, P, true>(in.bvh, L, p.sp, lights, vis, shadows, p.sums.c, rc, p.sums.trace)
                          : sumTerms<M, P>(in.bvh, L, p.sp, lights, vis, shadows, p.sums.c, rc);
}

/// What the groups of one sweep share.
struct Sweep {
    const LightingInputs& in;
    const LightArrays& L;
    const LightingPlan& plan;
    Accumulation* acc;     ///< the sums, or null: resolved into out
    LightingImage* out;
    std::uint64_t c0, c1;  ///< the chunks swept
    VisibilityOptions vis;
    bool shadows;          ///< off: V = 1, no shadow rays
};

/// Counting mode (the whole image: slot = px): pixel px's thread, with its work (hit pixels: `p`).
template <bool Count>
void recordPixel(const Sweep& s, std::size_t px, const GroupPixel* p) {
    if constexpr (Count) {
        const GBufferTexel& g = s.in.gbuffer.texels[px];
        ThreadCounters& t = s.in.counters->threads[px];
        recordTexel(t, g, s.in.particles, s.in.bvh, gpu_layout::kGBufferTexel);
        t.bytesWritten += gpu_layout::kRadiance;
        if (!p) return;
        t.trips = static_cast<std::uint32_t>(p->sums.c.lightTerms);
        t.bytesRead += t.trips * gpu_layout::kParticleRecord;
        t.addRays(p->rays, static_cast<std::uint32_t>(p->sums.c.shadowRays));
    }
}

/// The hit pixels of texels [x0, x1) of row y into pix, their particles'
/// records prefetched and their sums begun (loaded from the accumulation);
/// a miss's outputs are 0. Returns how many.
template <bool Count>
std::uint32_t beginGroup(const Sweep& s, std::uint32_t y, std::uint32_t x0, std::uint32_t x1, GroupPixel* pix) {
    const GBuffer& gb = s.in.gbuffer;
    const std::size_t row = std::size_t(y) * gb.width, rowSlot = gb.window.index(x0, y) - x0;
    std::uint32_t n = 0;
    for (std::uint32_t x = x0; x != x1; ++x) {
        const std::size_t slot = rowSlot + x;
        const std::uint32_t j = gb.texels[slot].particle;
        if (j == kNoParticle) {  // nothing to add: sums stay 0
            recordPixel<Count>(s, row + x, nullptr);
            if (!s.acc) {
                s.out->Lr[slot] = s.out->Lr_stderr[slot] = Vec3(0.0f);
                s.out->spp[slot] = s.out->rejected[slot] = 0.0f;
            }
            continue;
        }
        __builtin_prefetch(&s.in.particles.position[j]);
        __builtin_prefetch(&s.in.particles.albedo[j]);
        pix[n].px = row + x;
        pix[n++].slot = slot;
    }
    for (std::uint32_t k = 0; k < n; ++k) {
        GroupPixel& p = pix[k];
        p.sp = shadingPoint(gb.texels[p.slot], s.in.particles);
        p.sums = PixelSums{};
        p.sums.discardNonFinite = s.in.render.nonfinite == NonFinitePolicy::discard;
        p.rays = RayCounters{};
        if (s.acc) p.sums.load(*s.acc, p.slot);
        if (s.in.trace && s.in.trace->px == p.px) [[unlikely]] p.sums.trace = s.in.trace;
    }
    return n;
}

/// A group's hit pixels lit by the frame's estimator over the sweep's chunks.
template <ShadingModel M, Primitive P, bool Count>
void lightGroup(const Sweep& s, GroupPixel* pix, std::uint32_t n, std::unique_ptr<NearFieldCache>& cache) {
    const LightingInputs& in = s.in;
    withEstimatorKind(in.render.estimator, [&]<EstimatorKind K>() {
        constexpr const EstimatorInfo& e = estimatorInfo(K);
        if constexpr (e.reuse) {
            ACC_CHECK(!"a sweep of an estimator with reuse");  // restir's passes (render/restir/), never a sweep
        } else if constexpr (e.sums) {
            for (std::uint32_t k = 0; k < n; ++k) {
                PixelSums& sums = pix[k].sums;
                RayCounters* rc = Count ? &pix[k].rays : nullptr;
                const DVec3 v = sums.trace ? exactPixel<M, P, true>(in.bvh, s.L, pix[k].sp, s.vis, s.shadows, sums.c, rc, sums.trace)
                                           : exactPixel<M, P>(in.bvh, s.L, pix[k].sp, s.vis, s.shadows, sums.c, rc);
                if (finiteSum(v)) sums.sum = v;
                else sums.reject();  // a sum has one value: 0 either way
                sums.n = 1;
            }
        } else {
            if constexpr (e.nearField) {
                if (!cache) cache = std::make_unique<NearFieldCache>();
                std::uint64_t pinned = 0;  // the slots this group's pixels use
                std::uint32_t spares = 0;
                for (std::uint32_t k = 0; k < n; ++k)
                    if (!pix[k].sums.done) prepareNearField<M, P, Count>(in, s.L, s.vis, s.shadows, pix[k], *cache, pinned, spares);
            }
            runChunks<M, P, Count, K>(in, s.L, s.plan, s.vis, s.shadows, s.c0, s.c1, pix, n);
        }
    });
}

/// Each pixel's sums stored (or resolved into the image), its counters added to c.
template <bool Count>
void finishGroup(const Sweep& s, GroupPixel* pix, std::uint32_t n, LightingCounters& c) {
    for (std::uint32_t k = 0; k < n; ++k) {
        GroupPixel& p = pix[k];
        recordPixel<Count>(s, p.px, &p);
        if (s.acc) p.sums.store(*s.acc, p.slot);
        else p.sums.c.nonFinite += resolvePixel(p.sums.sum, p.sums.sumSq, p.sums.n, p.sums.rejected, s.plan.exact, *s.out, p.slot);
        p.sums.c.nonFinite += p.sums.rejected - p.sums.rejectedBefore;
        c += p.sums.c;
    }
}

/// What a sweep's thread keeps: its counters and its near-field cache.
struct SweepThread {
    LightingCounters counters;
    std::unique_ptr<NearFieldCache> nearCache;
};

/// A sweep's tile: columns [x0, x1), rows [y0, y1).
struct SweepTile {
    std::uint32_t x0, x1, y0, y1;
};

/// The sweeps' one parallel loop, compiled once rather than in each of the
/// 12 kernels (shading model x primitive x counting): tile(t, thread) over
/// rows [row0, row1) and columns [x0, x1) in 8x8 tiles on every core;
/// returns the threads' counters summed (integers: the same whatever the threads).
LightingCounters runSweepTiles(std::uint32_t row0, std::uint32_t row1, std::uint32_t x0, std::uint32_t x1,
                               const std::function<void(const SweepTile&, SweepThread&)>& tile) {
    tbb::enumerable_thread_specific<SweepThread> threads;
    tbb::parallel_for(tbb::blocked_range2d<std::uint32_t>(row0, row1, 8, x0, x1, 8), [&](const tbb::blocked_range2d<std::uint32_t>& r) {
        tile(SweepTile{r.cols().begin(), r.cols().end(), r.rows().begin(), r.rows().end()}, threads.local());
    });
    LightingCounters total;
    for (const SweepThread& t : threads) total += t.counters;
    return total;
}

/// Runs chunks [c0, c1) over every pixel of `area` (exact: of its rows that
/// the chunks are; a part of the G-buffer's window, whose layout `acc` and
/// `out` share) in one parallel sweep, each pixel's sums in registers:
/// loaded from and stored to `acc`, or (acc null: the whole frame in one
/// sweep) resolved straight into `out`. Pixels run in
/// groups of a tile row (runChunk). Counters (counting mode): per pixel, its
/// key, the light terms as loop trips, the shadow rays with their traversal
/// counts, and bytes.
template <ShadingModel M, Primitive P, bool Count>
LightingCounters sweep(const LightingInputs& in, const LightArrays& L, const LightingPlan& plan, Accumulation* acc,
                       LightingImage* out, std::uint64_t c0, std::uint64_t c1, Progress* progress,
                       const PixelWindow& area) {
    const GBuffer& gb = in.gbuffer;
    ACC_CHECK(gb.window.contains(area) && (!acc || acc->window == gb.window) && (acc || out->Lr.size() == gb.texels.size()));
    const Sweep s{in, L, plan, acc, out, c0, c1, VisibilityOptions::from(in.render), in.shading.visibility};
    const auto rows = [&](std::uint64_t c, std::uint32_t whole) {
        return plan.exact ? static_cast<std::uint32_t>(std::clamp<std::uint64_t>(c * LightingPlan::kChunkRows, area.y0, area.y1))
                          : whole;
    };
    const std::uint32_t row0 = rows(c0, area.y0), row1 = rows(c1, area.y1);
    if (row0 >= row1 || area.x0 >= area.x1) return {};
    return runSweepTiles(row0, row1, area.x0, area.x1, [&](const SweepTile& r, SweepThread& thread) {
        LightingCounters& c = thread.counters;
        GroupPixel pix[kGroupPixels];
        std::uint64_t hitPixels = 0;
        for (std::uint32_t y = r.y0; y != r.y1; ++y) {
            for (std::uint32_t x0 = r.x0; x0 < r.x1; x0 += kGroupPixels) {
                const std::uint32_t x1 = std::min(r.x1, x0 + kGroupPixels);
                // The next group's texels (the next row's at a row's end) are
                // read soon: a range's rows are short runs of the G-buffer.
                const std::size_t rowSlot = gb.window.index(x0, y) - x0;
                const std::size_t next = x1 < r.x1 ? rowSlot + x1 : rowSlot + gb.window.width() + r.x0;
                if (next + kGroupPixels <= gb.texels.size())
                    for (std::size_t b = 0; b < kGroupPixels * sizeof(GBufferTexel); b += 64)
                        __builtin_prefetch(reinterpret_cast<const char*>(&gb.texels[next]) + b);
                const std::uint32_t n = beginGroup<Count>(s, y, x0, x1, pix);
                if (n == 0) continue;
                hitPixels += n;
                lightGroup<M, P, Count>(s, pix, n, thread.nearCache);
                finishGroup<Count>(s, pix, n, c);
            }
        }
        // Work, not pixels: a hit pixel's samples (exact: its light terms, the
        // same count for every hit pixel); misses cost next to nothing.
        if (progress) progress->advance(hitPixels * (plan.exact ? 1 : c1 - c0));
    });
}

/// How long a band of a Monte Carlo sweep should take: what a stop request
/// or a due checkpoint waits for. A band is sized from the slowest pixel
/// seen so far, so a band of disk after sky rarely overshoots it.
constexpr double kBandSeconds = 2.0;

/// All chunks of acc.nextChunk.. plan.end, calling afterChunk between
/// sweeps. Monte Carlo: every remaining chunk of a band of pixels in one
/// sweep, bands in raster order (whole rows, or a run of one row when a row
/// would take longer than kBandSeconds: at 65536 spp a band is a few dozen
/// pixels), each sized by the time the slowest pixel took so far. So a
/// pixel's per-sweep work (split's near field) is done once per frame and
/// nothing is kept between sweeps, a crop's empty rows are passed once, and
/// a stop waits about kBandSeconds. The sums are those of chunk-major
/// sweeps, in the same order: the image does not depend on the bands.
/// exact: one sweep per chunk (a row). Counting mode: one sweep.
template <ShadingModel M, Primitive P, bool Count>
LightingCounters run(const LightingInputs& in, const LightArrays& L, const LightingPlan& plan, Accumulation& acc,
                     const ChunkHook& afterChunk, Progress* progress) {
    LightingCounters total;
    const PixelWindow w = in.gbuffer.window;  // a crop lights its window alone
    if (Count) {  // the GPU's dispatch: the whole frame, in one sweep
        total += sweep<M, P, Count>(in, L, plan, &acc, nullptr, acc.nextChunk, plan.end, progress, w);
        acc.nextChunk = plan.end;
        if (afterChunk) afterChunk(acc);
        return total;
    }
    double pixelChunkSeconds = 0.0;        // measured: the slowest pixel-chunk of a band so far
    std::uint32_t previous = 0;            // the largest band's pixels so far
    while (acc.nextChunk < plan.end) {
        const std::uint64_t c = acc.nextChunk;
        if (plan.exact) {
            total += sweep<M, P, Count>(in, L, plan, &acc, nullptr, c, c + 1, progress, w);
            acc.nextChunk = c + 1;
        } else {
            const std::uint64_t span = plan.end - c;
            const std::uint32_t pixels = nextBandPixels(pixelChunkSeconds, span, previous, kGroupPixels,
                                                        std::uint32_t(tbb::this_task_arena::max_concurrency()), kBandSeconds);
            const std::uint32_t row = std::max(acc.bandRows, w.y0), x0 = std::max(acc.bandCols, w.x0);
            PixelWindow band;
            if (x0 == w.x0 && pixels >= w.width())  // whole rows
                band = {w.x0, w.x1, row, std::min(w.y1, row + std::clamp(pixels / w.width(), 1u, LightingPlan::kBandRows))};
            else  // a run of this row
                band = {x0, std::min(w.x1, x0 + pixels), row, row + 1};
            const auto start = std::chrono::steady_clock::now();
            total += sweep<M, P, Count>(in, L, plan, &acc, nullptr, c, plan.end, progress, band);
            previous = std::max(previous, std::uint32_t(band.pixels()));
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            pixelChunkSeconds = std::max(pixelChunkSeconds, seconds / (double(band.pixels()) * double(span)));
            if (band.x1 == w.x1) {
                acc.bandRows = band.y1;
                acc.bandCols = 0;
            } else {
                acc.bandRows = band.y0;
                acc.bandCols = band.x1;
            }
            if (acc.bandRows >= w.y1) {
                acc.nextChunk = plan.end;
                acc.bandRows = acc.bandCols = 0;
            }
        }
        if (afterChunk && !afterChunk(acc)) break;
    }
    return total;
}

template <ShadingModel M>
LightingCounters dispatchPrimitive(const LightingInputs& in, const LightArrays& L, const LightingPlan& plan,
                                   Accumulation& acc, const ChunkHook& hook, Progress* p) {
    const bool spheres = in.bvh.settings().primitive == Primitive::sphere;
    if (in.counters)
        return spheres ? run<M, Primitive::sphere, true>(in, L, plan, acc, hook, p)
                       : run<M, Primitive::billboard, true>(in, L, plan, acc, hook, p);
    return spheres ? run<M, Primitive::sphere, false>(in, L, plan, acc, hook, p)
                   : run<M, Primitive::billboard, false>(in, L, plan, acc, hook, p);
}

}  // namespace

namespace {
/// The light samplers an estimator needs were built for it (the plan's
/// work): a missing one is a defect of the caller, not of the input.
void checkSamplerInputs(const LightingInputs& in) {
    const EstimatorInfo& e = estimatorInfo(in.render.estimator);
    const LightSamplerKind need = samplerFor(in.render);
    ACC_CHECK(!e.reuse);  // restir runs its own passes
    ACC_CHECK(need != LightSamplerKind::tree || in.lightTree);
    // ris draws its candidates in proportion to power exactly when given the
    // table: for it the table is there exactly when its source needs one.
    ACC_CHECK(e.resampling ? (need == LightSamplerKind::power) == (in.powerTable != nullptr)
                           : need != LightSamplerKind::power || in.powerTable);
    ACC_CHECK(!e.resampling || !sourceInfo(in.render.source).presampled);
}
}  // namespace

LightingCounters accumulateLighting(const LightingInputs& in, const LightingPlan& plan, Accumulation& acc,
                                    const ChunkHook& afterChunk, Progress* progress) {
    ACC_CHECK(acc.width == in.gbuffer.width && acc.height == in.gbuffer.height && acc.window == in.gbuffer.window);
    if (in.particles.empty() || acc.nextChunk >= plan.end) return {};
    checkSamplerInputs(in);
    const LightArrays L(in.particles, in.shading);
    switch (in.shading.model) {
    case ShadingModel::lambert: return dispatchPrimitive<ShadingModel::lambert>(in, L, plan, acc, afterChunk, progress);
    case ShadingModel::sphere: return dispatchPrimitive<ShadingModel::sphere>(in, L, plan, acc, afterChunk, progress);
    case ShadingModel::isotropic: return dispatchPrimitive<ShadingModel::isotropic>(in, L, plan, acc, afterChunk, progress);
    }
    return {};
}

void allocate(LightingImage& out, std::size_t pixels) {
    out.Lr.resize(pixels);
    out.Lr_stderr.resize(pixels);
    out.spp.resize(pixels);
    out.rejected.resize(pixels);
}

void resolveLighting(const Accumulation& acc, bool exact, LightingImage& out, std::uint64_t* nonFinite) {
    allocate(out, acc.pixels());
    tbb::enumerable_thread_specific<std::uint64_t> zeroed(0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, acc.pixels(), 4096), [&](const auto& r) {
        std::uint64_t& z = zeroed.local();
        for (std::size_t px = r.begin(); px != r.end(); ++px)
            z += resolvePixel(acc.sum[px], acc.sumSq[px], acc.n[px], acc.rejected[px], exact, out, px);
    });
    if (nonFinite)
        for (const std::uint64_t z : zeroed) *nonFinite += z;
}

/// The whole frame in one sweep, each pixel resolved as it finishes (no
/// Accumulation in memory): the same sums, in the same order, as chunk sweeps.
template <ShadingModel M>
LightingCounters directPrimitive(const LightingInputs& in, const LightArrays& L, const LightingPlan& plan,
                                 LightingImage& out, Progress* p) {
    const bool spheres = in.bvh.settings().primitive == Primitive::sphere;
    const std::uint64_t c0 = plan.begin, c1 = plan.end;
    const PixelWindow& w = in.gbuffer.window;  // a crop lights its window alone
    if (in.counters)
        return spheres ? sweep<M, Primitive::sphere, true>(in, L, plan, nullptr, &out, c0, c1, p, w)
                       : sweep<M, Primitive::billboard, true>(in, L, plan, nullptr, &out, c0, c1, p, w);
    return spheres ? sweep<M, Primitive::sphere, false>(in, L, plan, nullptr, &out, c0, c1, p, w)
                   : sweep<M, Primitive::billboard, false>(in, L, plan, nullptr, &out, c0, c1, p, w);
}

LightingCounters estimateLighting(const LightingInputs& in, LightingImage& out, Progress* progress) {
    const std::size_t pixels = in.gbuffer.texels.size();
    if (in.particles.empty()) {
        out.Lr.assign(pixels, Vec3(0.0f));
        out.Lr_stderr.assign(pixels, Vec3(0.0f));
        out.spp.assign(pixels, 0.0f);
        out.rejected.assign(pixels, 0.0f);
        return {};
    }
    checkSamplerInputs(in);
    allocate(out, pixels);
    const LightingPlan plan = planLighting(in.render, in.gbuffer.height);
    const LightArrays L(in.particles, in.shading);
    switch (in.shading.model) {
    case ShadingModel::lambert: return directPrimitive<ShadingModel::lambert>(in, L, plan, out, progress);
    case ShadingModel::sphere: return directPrimitive<ShadingModel::sphere>(in, L, plan, out, progress);
    case ShadingModel::isotropic: return directPrimitive<ShadingModel::isotropic>(in, L, plan, out, progress);
    }
    return {};
}

}  // namespace accretion
