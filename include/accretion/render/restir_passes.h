#pragma once
// The per-texel bodies of ReSTIR DI's passes (docs/MODEL.md section 4),
// written once for the CPU and the GPU twin, as RTXDI writes its resampling
// functions once over its RAB_* bridge. A body reads the frame, records what
// one GPU thread does, and writes its output only through a bridge B:
//
//   using Rng                                the pixel streams (Rng on the CPU, PortableRng on
//                                            the GPU: the same numbers)
//   const ReuseParams& params()              the pass's settings and grid
//   GBufferTexel texel(px)                   this frame's lighting-grid texel
//   StoredReservoir input(px)                the pass's input reservoir
//   void output(px, r)                       the pass's output, as it is
//   void keep(px, r)                         the output as the frame keeps reservoirs (the codec)
//   bool reject(px)                          a non-finite value at px counted; true when
//                                            render.nonfinite discards the reservoir
//   Rec recorder(px, g)                      the thread's counters (Recorder<Count> on the CPU,
//                                            NoRecorder on the GPU), its branch key recorded
//   std::uint32_t reservoirBytes()           a stored reservoir's bytes (the codec's)
//   void reuse(ReuseOutcome o)               an offered history or neighbour kept or refused, and why
//   void historyCapped()                     temporal: a kept history's M was cut to m_cap x M
//   Offers offers<N>()                       an empty list of at most N offers:
//                                              addCurrent(r, g)  a reservoir of this frame at texel g
//                                              addHistory(r, q)  last frame's reservoir at its texel q
//                                              combine(rng)      restir_steps.h's combineReservoirs
//   history: bool historyHas(j), Vec3 historyPosition(j), const Camera& historyCamera(),
//            GBufferTexel historyTexel(q), StoredReservoir historyReservoir(q)
//   lights:  ShadingPoint shadingPoint(g); float targetPdf(sp, i) (a light term counted);
//            bool lightTerm(sp, i, t) (not counted); void countLightTerm();
//            std::uint32_t clusterOf(i) (counting mode's SER hint)
//   shadows: bool shadows() (plan.shadowRays); bool visible(sp, i, t, rec) (a shadow ray traced
//            and counted); void occluded() (one found blocked); bool dropOccludedCandidates()
//            (restir.candidate_visibility); bool visibilityReuse(); void writeLr(px, Lr)
//
// generateCandidates also takes a candidate source S: reads(), gathers()
// per candidate (its records and table entries), and at(sp, x, y, rng) the
// receiver's drawer, whose sample(rng) gives a LightSample.
//
// The CPU's bridge is src/render/restir/cpu_bridge.h (Embree, counters, the
// reservoir codec), the twin's src/twin/device_bridge.h (OptiX, nothing
// counted). tests/twin/shared_core_check.cu runs these bodies on the GPU and
// on the CPU through one bridge of its own and compares them bit for bit.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "accretion/core/rng.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/render/restir_steps.h"
#include "accretion/render/reuse_outcome.h"

namespace accretion::restir {

/// What the reuse passes read of the settings and the lighting grid.
struct ReuseParams {
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
    std::uint32_t width = 0, height = 0;  ///< the lighting grid (this frame's and the history's)
    float scale = 1.0f;                   ///< lighting / image resolution
    float normalThreshold = 0.9f, depthThreshold = 0.1f;
    double mCap = 20.0;                   ///< restir.m_cap
    std::uint32_t candidates = 16;        ///< render.candidates
    std::uint32_t neighbours = 0;         ///< restir.spatial_neighbours
    float radius = 1.0f;                  ///< spatial disc radius in lighting texels (>= 1)
    /// A lighting grid that is a window of the frame's (restir.crop_margin):
    /// the whole grid's width and the window's origin in it (0: the grid is
    /// the whole). A texel's streams are keyed by its index in the whole
    /// grid, so a window draws each texel's numbers as the whole frame does.
    std::uint32_t wholeWidth = 0, originX = 0, originY = 0;
    /// particle_restir (particle_restir_passes.h): the grid is the visible
    /// particles' billboard texels, texelsPerParticle() consecutive texels a
    /// particle (texelLayers layers of texelSide x texelSide), in its slot.
    std::uint32_t texelSide = 0;       ///< texels per billboard side (0: the grid is the image's pixels)
    std::uint32_t texelLayers = 1;     ///< restir.texel_rays: independent reservoirs per texel
    std::uint32_t worldNeighbours = 8; ///< restir.world_neighbours: slots either side spatial reuse draws from
    std::uint32_t visible = 0;         ///< visible particles (slots) this frame
    float texelHistory = 0.0f;         ///< restir.texel_history: weight of a texel's last Lr
    ACC_HD std::uint32_t texelsPerParticle() const { return texelSide * texelSide * texelLayers; }
    /// The streams of texel px showing g: a pixel's by its place in the
    /// whole grid; a particle texel's by its particle and its place on it,
    /// so that it draws the same numbers whatever else is visible.
    ACC_HD std::uint64_t streamKey(std::size_t px, const GBufferTexel& g) const {
        if (texelSide != 0) return (std::uint64_t(1) << 62) | (std::uint64_t(g.particle) * texelsPerParticle() + px % texelsPerParticle());
        return pixelKey(px);
    }
    /// Texel px of a grid of pixels by its place in the whole grid.
    ACC_HD std::uint64_t pixelKey(std::size_t px) const {
        if (wholeWidth == 0) return px;
        return (std::uint64_t(px / width) + originY) * wholeWidth + px % width + originX;
    }
};

/// The ReuseParams of a frame: the lighting grid (width x height, `scale` x
/// the image), the frame and seed of its streams, and the settings; the CPU
/// and the twin both make theirs here.
inline ReuseParams reuseParams(const Settings& s, std::uint32_t frame, std::uint64_t seed, std::uint32_t width,
                               std::uint32_t height, float scale) {
    ReuseParams p;
    p.frame = frame;
    p.seed = seed;
    p.width = width;
    p.height = height;
    p.scale = scale;
    p.normalThreshold = float(s.restir.normal_threshold);
    p.depthThreshold = float(s.restir.depth_threshold);
    p.mCap = s.restir.m_cap;
    p.candidates = s.render.candidates;
    p.neighbours = s.restir.spatial_neighbours;
    p.radius = std::max(1.0f, float(s.restir.spatial_radius) * scale);
    if (s.render.estimator == EstimatorKind::particle_restir) {
        p.texelSide = s.restir.texels;
        p.texelLayers = s.restir.texel_rays;
        p.worldNeighbours = s.restir.world_neighbours;
        p.texelHistory = float(s.restir.texel_history);
    }
    return p;
}

/// The counters of a thread that counts nothing (the GPU's bridge).
struct NoRecorder {
    static constexpr bool on = false;
    ACC_HD void hint(std::uint32_t) {}
    ACC_HD void trip(std::uint32_t = 1) {}
    ACC_HD void read(std::uint32_t) {}
    ACC_HD void gather(std::uint32_t) {}
    ACC_HD void write(std::uint32_t) {}
};

/// generateCandidates at texel (x, y) = px: RIS of `candidates` lights from
/// the source with target p_hat (no visibility), resampleCandidates of
/// restir_steps.h; with candidate_visibility an occluded winner is dropped
/// before reuse (Bitterli et al. 2020, Alg. 5).
template <class B, class Source>
ACC_HD_BODY void generateCandidatesTexel(B& b, const Source& source, std::size_t px, std::uint32_t x, std::uint32_t y) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto&& rec = b.recorder(px, g);
    b.output(px, StoredReservoir{});
    if (!g.hit()) return;
    const std::uint32_t M = p.candidates;
    rec.trip(M);
    rec.read(M * source.reads());  // per candidate its light's record and the source's entries
    rec.gather(M * source.gathers());
    rec.write(b.reservoirBytes());
    const ShadingPoint sp = b.shadingPoint(g);
    typename B::Rng rng(p.streamKey(px, g), p.frame, RngPass::restirCandidates, p.seed);
    const auto drawer = source.at(sp, x, y, rng);
    Reservoir r;
    if (!resampleCandidates(
            M, rng, [&](typename B::Rng& u) { return drawer.sample(u); }, [&](std::uint32_t i) { return b.targetPdf(sp, i); },
            [&] { return b.reject(px); }, r))
        return;  // the output stays empty
    if (b.dropOccludedCandidates() && r.W > 0.0f) {
        LightTerm t;
        if (b.lightTerm(sp, r.y, t) && !b.visible(sp, r.y, t, rec)) {
            b.occluded();
            r.W = 0.0f;
        }
    }
    b.keep(px, StoredReservoir::of(r));
}

/// temporalResampling's step once texel px (showing g, this frame's
/// reservoir cur) has found its history, last frame's reservoir at q: that
/// reservoir's M capped at m_cap x M, the two combined
/// (restir.bias_correction) and kept at px. restir's reprojection and
/// particle_restir's id both end here.
template <class B>
ACC_HD_BODY void combineWithHistory(B& b, std::size_t px, const GBufferTexel& g, const StoredReservoir& cur, std::size_t q) {
    const ReuseParams& p = b.params();
    auto offers = b.template offers<2>();
    offers.addCurrent(cur, g);
    StoredReservoir prev = b.historyReservoir(q);
    const std::uint32_t historyM = prev.M;
    prev.M = capHistoryM(prev.M, cur.M, p.mCap);
    if (prev.M != historyM) b.historyCapped();
    offers.addHistory(prev, q);
    typename B::Rng rng(p.streamKey(px, g), p.frame, RngPass::restirTemporal, p.seed);
    b.keep(px, sanitizeReservoir(offers.combine(rng), [&] { return b.reject(px); }));
}

/// The kept sample r shaded at sp: its light term (counted), its shadow ray
/// when shadows are on (traced and counted on rec), and Lr = f I G V W by
/// shadeSample's outcome. False when the light term is zero (Lr stays 0).
template <class B, class Rec>
ACC_HD_BODY bool shadeKeptSample(B& b, const ShadingPoint& sp, const StoredReservoir& r, Rec& rec, Shade& shade, Vec3& Lr) {
    LightTerm t;
    b.countLightTerm();
    if (!b.lightTerm(sp, r.y, t)) return false;
    bool seen = true;
    if (b.shadows()) {
        rec.trip();
        seen = b.visible(sp, r.y, t, rec);
    }
    shade = shadeSample(t, r.W, seen, Lr);
    return true;
}

/// temporalResampling at texel px: the surface point where it was last frame
/// (moved back by its particle's motion), projected with the previous camera
/// onto the previous lighting grid; rejected on another particle, normal or
/// depth; the history's M capped at m_cap x M; combined with this frame's
/// reservoir (restir.bias_correction).
template <class B>
ACC_HD_BODY void temporalResamplingTexel(B& b, std::size_t px) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto&& rec = b.recorder(px, g);
    const StoredReservoir cur = b.input(px);
    b.output(px, cur);
    if (!g.hit()) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip();
    rec.read(R + 2 * gpu_layout::kParticleRecord);  // the reservoir, the particle now and before
    rec.gather(2);
    rec.write(R);
    const std::uint32_t j = g.particle;
    if (!b.historyHas(j)) {
        b.reuse(ReuseOutcome::noHistory);
        return;
    }
    const Vec3 xPrev = b.historyPosition(j) + g.local;  // frame-independent: relative to the particle
    float depth;
    std::size_t q = 0;
    if (!reprojectPoint(b.historyCamera(), xPrev, p.scale, p.width, p.height, q, depth)) {
        b.reuse(ReuseOutcome::offScreen);
        return;
    }
    rec.read(gpu_layout::kGBufferTexel);
    const GBufferTexel gp = b.historyTexel(q);
    const ReuseOutcome o = gp.particle != j ? ReuseOutcome::particle
                                            : resampling::surfaceOutcome(g.normal, depth, gp.normal, gp.depth, p.normalThreshold,
                                                                         p.depthThreshold, ReuseOutcome::sameParticle);
    b.reuse(o);
    if (!kept(o)) return;
    rec.read(R + gpu_layout::kParticleRecord);  // the previous reservoir and its light
    rec.gather(1);
    combineWithHistory(b, px, g, cur, q);
}

/// A spatial pass's body at texel px, iteration `iteration`: this texel's
/// reservoir and p.neighbours neighbours, each drawn by draw(rng, q) (false:
/// off the grid, or this texel) and judged by outcome(g, gn) (kept or
/// refused, and why), combined (restir.bias_correction) and kept at px.
/// restir's disc of pixels and particle_restir's world neighbours differ
/// only in those two.
template <class B, class Draw, class Outcome>
ACC_HD_BODY void resampleNeighbours(B& b, std::size_t px, std::uint32_t iteration, Draw&& draw, Outcome&& outcome) {
    const ReuseParams& p = b.params();
    const GBufferTexel g = b.texel(px);
    auto&& rec = b.recorder(px, g);
    b.output(px, b.input(px));
    if (!g.hit()) return;
    const std::uint32_t R = b.reservoirBytes();
    rec.trip(p.neighbours);
    rec.read(R + gpu_layout::kParticleRecord);
    rec.gather(1);
    rec.write(R);
    typename B::Rng rng(p.streamKey(px, g) ^ (std::uint64_t(iteration) << 40), p.frame, RngPass::restirSpatial, p.seed);
    auto offers = b.template offers<kMaxOffers>();
    offers.addCurrent(b.input(px), g);
    for (std::uint32_t s = 0; s < p.neighbours; ++s) {
        std::size_t q;
        if (!draw(rng, q)) {
            b.reuse(ReuseOutcome::offScreen);
            continue;
        }
        const GBufferTexel gn = b.texel(q);
        rec.read(gpu_layout::kGBufferTexel);
        const ReuseOutcome o = outcome(g, gn);
        b.reuse(o);
        if (!kept(o)) continue;
        rec.read(R + gpu_layout::kParticleRecord);
        rec.gather(1);
        offers.addCurrent(b.input(q), gn);
    }
    b.keep(px, sanitizeReservoir(offers.combine(rng), [&] { return b.reject(px); }));
}

/// spatialResampling at texel (x, y) = px, iteration `iteration`: k
/// neighbours uniform in a disc of the radius (drawNeighbour), rejected off
/// the grid, on a miss, or on normal and depth; combined with this texel's
/// reservoir (restir.bias_correction).
template <class B>
ACC_HD_BODY void spatialResamplingTexel(B& b, std::size_t px, std::uint32_t x, std::uint32_t y, std::uint32_t iteration) {
    const ReuseParams& p = b.params();
    resampleNeighbours(
        b, px, iteration,
        [&](typename B::Rng& rng, std::size_t& q) { return drawNeighbour(rng, p.radius, x, y, p.width, p.height, q); },
        [&](const GBufferTexel& g, const GBufferTexel& gn) {
            return !gn.hit() ? ReuseOutcome::miss
                             : resampling::surfaceOutcome(g.normal, g.depth, gn.normal, gn.depth, p.normalThreshold, p.depthThreshold,
                                                          gn.particle == g.particle ? ReuseOutcome::sameParticle
                                                                                    : ReuseOutcome::otherParticle);
        });
}

/// traceShadowRays at texel px: one shadow ray for the kept sample, Lr =
/// f I G V W (shadeSample); with visibility reuse an occluded sample's
/// reservoir keeps its M alone; an overflowing one is a zero sample
/// (render.nonfinite decides on the reservoir). Reads and writes the
/// bridge's output reservoir in place.
template <class B>
ACC_HD_BODY void traceShadowRayTexel(B& b, std::size_t px) {
    b.writeLr(px, Vec3(0.0f));
    const GBufferTexel g = b.texel(px);
    auto&& rec = b.recorder(px, g);
    rec.write(gpu_layout::kRadiance);
    if (!g.hit()) return;
    const StoredReservoir r = b.input(px);
    const std::uint32_t R = b.reservoirBytes();
    rec.read(R);
    if (!(r.W > 0.0f)) return;
    rec.read(gpu_layout::kParticleRecord);
    rec.gather(1);
    if constexpr (std::decay_t<decltype(rec)>::on) rec.hint(b.clusterOf(r.y));
    Shade shade;
    Vec3 Lr(0.0f);
    if (!shadeKeptSample(b, b.shadingPoint(g), r, rec, shade, Lr)) return;
    switch (shade) {
    case Shade::lit: b.writeLr(px, Lr); break;
    case Shade::occluded:
        b.occluded();
        if (b.visibilityReuse()) {
            b.keep(px, occludedReservoir(r));
            rec.write(R);
        }
        break;
    case Shade::overflow:  // a zero sample (discard: and no reservoir for reuse)
        if (b.reject(px)) b.keep(px, StoredReservoir{});
        break;
    }
}

}  // namespace accretion::restir
