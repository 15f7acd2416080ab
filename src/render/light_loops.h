#pragma once
// What the Monte Carlo sweep (estimators.cpp) and split's pilot
// (choose_near_lights.cpp) share, internal to src/render/: the CPU's bridge
// of light_estimates.h and the light loops over it, a pixel's running sums,
// the draw of a chunk's lights, and a particle's near-field search.
#include <cstdint>
#include <span>

#include "accretion/core/rng.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/lighting/near_field.h"
#include "accretion/render/estimators.h"
#include "accretion/render/light_estimates.h"
#include "accretion/render/sample_sums.h"
#include "accretion/render/visibility.h"

namespace accretion::light_loops {

/// V(x, p_i) of a light with a non-zero term t: one shadow ray, counted
/// (visibility off: 1, no ray).
template <Primitive P>
inline bool seen(const ParticleBvh& bvh, const LightArrays& L, const ShadingPoint& sp, std::uint32_t i, const LightTerm& t,
                 const VisibilityOptions& vis, bool shadows, LightingCounters& c, RayCounters* rc) {
    if (!shadows) return true;
    ++c.shadowRays;
    if (visible<P>(bvh, vis, sp, i, L.packed[i].position, L.packed[i].radius, t, rc)) return true;
    ++c.shadowOccluded;
    return false;
}

/// light_estimates.h's bridge on the CPU: Embree's shadow rays counted
/// (seen), render --pixel's records when Traced (a template argument: the
/// light loop of every other pixel has no trace test).
template <ShadingModel M, Primitive P, bool Traced>
struct CpuLightBridge {
    static constexpr bool traced = Traced;
    const ParticleBvh& bvh;
    const LightArrays& L;
    const VisibilityOptions& vis;
    bool shadows;
    LightingCounters& c;
    RayCounters* rc;
    PixelTrace* trace;

    bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const { return L.term<M>(sp, i, t); }
    void countLightTerm() { ++c.lightTerms; }
    bool seen(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) {
        return light_loops::seen<P>(bvh, L, sp, i, t, vis, shadows, c, rc);
    }
    void traceLight() { ++trace->lightsSeen; }
    void traceTerm(std::uint32_t i, const LightTerm& t, bool v) { trace->terms.push_back({i, t.value, v}); }
    void traceSample(const LightSample& x, bool term, const LightTerm& t, bool v) {
        trace->samples.push_back({x.i, x.pdf, term ? t.value : Vec3(0.0f), v, v ? Vec3(DVec3(t.value) / double(x.pdf)) : Vec3(0.0f)});
    }
};

/// The sum of f I G V over `lights` (every light i != j for exact; the near
/// field for split): light_estimates.h's sumLightTerms.
/// With a trace (render --pixel), every non-zero term and its V are recorded.
template <ShadingModel M, Primitive P, bool Traced = false, class Lights>
DVec3 sumTerms(const ParticleBvh& bvh, const LightArrays& L, const ShadingPoint& sp, const Lights& lights,
               const VisibilityOptions& vis, bool shadows, LightingCounters& c, RayCounters* rc, PixelTrace* trace = nullptr) {
    CpuLightBridge<M, P, Traced> b{bvh, L, vis, shadows, c, rc, trace};
    return sumLightTerms(b, sp, lights);
}

/// exact: every light i != j.
template <ShadingModel M, Primitive P, bool Traced = false>
DVec3 exactPixel(const ParticleBvh& bvh, const LightArrays& L, const ShadingPoint& sp, const VisibilityOptions& vis, bool shadows,
                 LightingCounters& c, RayCounters* rc, PixelTrace* trace = nullptr) {
    return sumTerms<M, P, Traced>(bvh, L, sp, LightRange{L.count}, vis, shadows, c, rc, trace);
}

/// One pixel's running sums (SampleSums: the non-finite policy applied to
/// every sample added) and counters while its chunks run, loaded from and
/// stored to the Accumulation, or resolved directly.
struct PixelSums : SampleSums {
    std::uint8_t done = 0;
    std::uint32_t rejectedBefore = 0;  ///< `rejected` when loaded: the sweep's rejections are the rest
    LightingCounters c;   ///< this pixel's work (added to its thread's when it finishes)
    PixelTrace* trace = nullptr;  ///< render --pixel: this is the pixel traced

    void load(const Accumulation& a, std::size_t px) {
        sum = a.sum[px];
        sumSq = a.sumSq[px];
        n = a.n[px];
        rejected = rejectedBefore = a.rejected[px];
        done = a.done[px];
    }
    void store(Accumulation& a, std::size_t px) const {
        a.sum[px] = sum;
        a.sumSq[px] = sumSq;
        a.n[px] = n;
        a.rejected[px] = rejected;
        a.done[px] = done;
    }
};

/// Mean, standard error, spp and rejected count of one pixel's sums into
/// `out` (resolveSums). Returns 1 if the value was zeroed.
inline std::uint32_t resolvePixel(const DVec3& sum, const DVec3& sumSq, std::uint32_t n, std::uint32_t rejected, bool exact,
                           LightingImage& out, std::size_t px) {
    const std::uint32_t zeroed = resolveSums(sum, sumSq, n, exact, out.Lr[px], out.Lr_stderr[px], out.spp[px]) ? 1 : 0;
    out.rejected[px] = float(rejected + zeroed);
    return zeroed;
}

/// The lights of one chunk of uniform / power / tree / split (far) samples,
/// in stream order, their records prefetched (a random light is a cache miss);
/// `near`: split's near field (null for the others).
template <EstimatorKind K>
void drawLights(const LightingInputs& in, const LightArrays& L, const ShadingPoint& sp, const NearField* near, Rng& rng,
                std::uint32_t count, LightSample* xs) {
    constexpr const EstimatorInfo& e = estimatorInfo(K);
    for (std::uint32_t k = 0; k < count; ++k) {
        if constexpr (e.sampler == LightSamplerKind::power) xs[k] = sampleSource<true>(L, in.powerTable, rng);
        else if constexpr (e.sampler == LightSamplerKind::tree && e.nearField) xs[k] = in.lightTree->sampleFar(sp, *near, rng);
        else if constexpr (e.sampler == LightSamplerKind::tree) xs[k] = in.lightTree->sample(sp, rng);
        else xs[k] = sampleSource<false>(L, nullptr, rng);
        if (xs[k].i < L.count) {
            __builtin_prefetch(&L.packed[xs[k].i]);
            in.bvh.prefetchExclusion(xs[k].i);
        }
    }
}

/// uniform / power / tree / split's far samples: light_estimates.h's
/// shadeLightSamples into a pixel's sums.
template <ShadingModel M, Primitive P, bool Traced = false>
void shadeSamples(const ParticleBvh& bvh, const LightArrays& L, const ShadingPoint& sp, const LightSample* xs,
                  std::uint32_t count, const DVec3& near, const VisibilityOptions& vis, bool shadows, PixelSums& acc,
                  RayCounters* rc) {
    CpuLightBridge<M, P, Traced> b{bvh, L, vis, shadows, acc.c, rc, acc.trace};
    shadeLightSamples(b, sp, xs, count, near, acc);
}


/// Particle j's centre with normal n, where its near field is found for
/// all its pixels. Lambert: n is the billboard's, the same for every pixel
/// of j; the other models' cuts do not use it.
inline ShadingPoint particleCentre(const LightingInputs& in, std::uint32_t j, const Vec3& n) {
    ShadingPoint centre{};
    centre.x = in.particles.position[j];
    centre.n = n;
    centre.self = j;
    return centre;
}

/// The k lights nearest to particle j's centre, other than j, and the far
/// cut of at most `cutNodes` nodes seen from there: the near field of every
/// pixel on j.
inline void nearestToParticle(const LightingInputs& in, std::uint32_t j, std::uint32_t k, const Vec3& n, std::uint32_t cutNodes,
                       NearField& out) {
    in.lightTree->nearest(particleCentre(in, j, n), k, out, cutNodes);
}

}  // namespace accretion::light_loops
