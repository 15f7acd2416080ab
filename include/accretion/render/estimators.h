#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/progress.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/render/reuse_outcome.h"
#include "accretion/render/accumulation.h"
#include "accretion/render/pixel_window.h"
#include "accretion/render/gbuffer.h"
#include "accretion/render/reuse_outcome.h"
#include "accretion/render/pixel_trace.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Per-pixel estimate of the reflected light Lr, of the G-buffer's window (row by row).
struct LightingImage {
    std::vector<Vec3> Lr;        ///< estimate
    std::vector<Vec3> Lr_stderr; ///< standard error of the estimate (0 for exact)
    std::vector<float> spp;      ///< light samples per pixel (N-1 terms for exact: 0 is written)
    std::vector<float> rejected; ///< non-finite samples rejected (render.nonfinite)
};

/// Counts of the lighting pass, summed over threads (integers: deterministic).
struct LightingCounters {
    std::uint64_t lightTerms = 0;     ///< unshadowed terms evaluated
    std::uint64_t shadowRays = 0;     ///< occlusion queries
    std::uint64_t shadowOccluded = 0; ///< queries that found a blocker
    ReuseCounts reuse;                ///< restir: temporal histories and spatial neighbours offered, by outcome
    std::uint64_t nonFinite = 0;      ///< NaN/Inf samples rejected (render.nonfinite)
    LightingCounters& operator+=(const LightingCounters& o) {
        nonFinite += o.nonFinite;
        lightTerms += o.lightTerms;
        shadowRays += o.shadowRays;
        shadowOccluded += o.shadowOccluded;
        reuse += o.reuse;
        return *this;
    }
};

/// Non-finite values rejected, per pass (render.nonfinite).
using PassRejections = std::map<Pass, std::uint64_t>;

/// Reuse offers by outcome, per pass (temporalResampling, spatialResampling).
using PassReuse = std::map<Pass, ReuseCounts>;

/// Everything the lighting estimators read.
struct LightingInputs {
    const ParticleBvh& bvh;
    const Particles& particles;
    const GBuffer& gbuffer;
    const ShadingSettings& shading;
    const RenderSettings& render;
    std::uint32_t frame = 0;
    const AliasTable* powerTable = nullptr;  ///< power (required); ris: candidates in proportion to power when given
    const LightTree* lightTree = nullptr;    ///< required by `tree`, and by ris with render.source = tree
    PassCounters* counters = nullptr;        ///< counting mode: one thread record per pixel (the BVH must count)
    PixelTrace* trace = nullptr;             ///< render --pixel: record the terms or samples of trace->px
    std::uint32_t nearLights = 0;            ///< split with render.near_lights = 0: the frame's chooseNearLights k
};

/// Called after each chunk with the sums so far; returning false stops the
/// frame there (a checkpoint can restart it from acc.nextChunk).
using ChunkHook = std::function<bool(const Accumulation&)>;

/// Add the chunks [acc.nextChunk, plan.end) of the frame to `acc` (which
/// must be reset() for the frame and the G-buffer's window, or restored
/// from a checkpoint). Counting mode runs them in one sweep. Returns the counters of the chunks run.
LightingCounters accumulateLighting(const LightingInputs& in, const LightingPlan& plan, Accumulation& acc,
                                    const ChunkHook& afterChunk = {}, Progress* progress = nullptr);

/// The estimate, its standard error, spp and rejected counts from the sums
/// (of acc.window's pixels, as they are held). A value that is not finite in
/// float is zeroed and counted in `rejected`.
void resolveLighting(const Accumulation& acc, bool exact, LightingImage& out, std::uint64_t* nonFinite = nullptr);

/// split with render.near_lights = 0: the frame's k, from a pilot on a
/// low-resolution image of the frame's view (docs/MODEL.md section 4).
struct NearLightChoice {
    struct Candidate {
        std::uint32_t k = 0;        ///< near lights (at most N - 1)
        double relVariance = 0.0;   ///< V(k): one far sample's variance over the estimate squared (+ 1e-2), mean over pilot pixels and RGB
        double cost = 0.0;          ///< per pixel, in near lights: k + rho S (rho: kFarSampleCost)
    };
    /// A far sample (a cut node, a short descent, a term, a long shadow ray)
    /// costs as much as this many near lights (their search and far cut
    /// shared by a particle's pixels, a term and a short ray each): measured
    /// on disk_100k at 1920x1080, k = 1024, on the 2-core EPYC VM at 3e803b0:
    /// 0.40 us per far sample, 0.094 us per near light, per lit pixel on both
    /// cores (bench/split_1080p.sh: 0.253 s per spp and 61 s of near field
    /// over 634K lit pixels).
    static constexpr double kFarSampleCost = 4.3;
    std::uint32_t k = 0;            ///< the choice: least relVariance x cost
    std::uint32_t pixels = 0;       ///< pilot pixels (lit)
    std::vector<Candidate> candidates;
};

/// The pilot: each lit pixel of `pilot.gbuffer` (at most 256, evenly
/// spaced), for k = 16, 32, ..., NearField::kMaxNear: its particle's near
/// field and 64 far samples on fixed streams (RngPass::nearLightPilot);
/// the exact near sum at its point for the largest k (the estimate). Picks the k of least V(k) x (k +
/// rho S) for S = render.samples: the error x time of a render of S samples.
/// Deterministic: the same k for any crop, shard, resume or thread count.
NearLightChoice chooseNearLights(const LightingInputs& pilot);

/// The lights summed exactly per receiver by `split`: render.near_lights,
/// or when 0 `chosen`, the frame's chooseNearLights (which must have run).
std::uint32_t nearLightCount(const RenderSettings& render, std::uint32_t chosen);

/// The most nodes in `split`'s far cut (NearField): twice render.samples
/// as a power of 2 in [kMinFarCut, NearField::kMaxCut]. A cut of M nodes
/// costs about M importance bounds once per near field and saves about
/// log2(M) levels of the descent on every far sample of the particle's
/// pixels, and it is what draws the lights just beyond a small near field
/// in proportion to their terms: on disk_100k at 1080p with k = 16 and
/// 16 spp, relMSE x spp is 2.8 with 32 nodes and 0.42 with 256, for the
/// same time (8.1 and 8.3 s). At k = 1024, 1024 nodes was the fastest at 512 spp.
inline constexpr std::uint32_t kMinFarCut = 256;
std::uint32_t farCutSize(const RenderSettings& render);

/// estimateLighting (docs/MODEL.md sections 3-4): `exact` sums every light i != j
/// with one shadow ray each; `uniform` / `power` / `tree` average one-sample
/// estimates f I G V / p(i) (S per round, more rounds until target_stderr);
/// `split` adds to each sample the exact sum over the receiver's nearest
/// lights and draws the one light from the rest (LightTree::sampleFar);
/// `ris` averages S one-reservoir RIS estimates of M candidates each. Monte
/// Carlo estimators also give their standard error. (`restir` keeps history
/// across frames: see render/restir.h.)
/// Per-pixel, per-chunk PCG streams make the result independent of the
/// thread count and of checkpoints. A NaN/Inf sample is rejected under
/// render.nonfinite and counted. The whole frame in one call:
LightingCounters estimateLighting(const LightingInputs& in, LightingImage& out, Progress* progress = nullptr);

}  // namespace accretion
