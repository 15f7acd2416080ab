#pragma once
// The CPU's bridge of the shared pass bodies (accretion/render/restir_passes.h):
// the frame's buffers, Embree for shadow rays, the counters of counting
// mode, the reservoir codec.
#include <algorithm>
#include <optional>

#include "accretion/core/error.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/render/restir_passes.h"
#include "combine_reservoirs.h"
#include "restir_pass.h"

namespace accretion::restir {

/// The ReuseParams of a CPU frame.
inline ReuseParams reuseParams(const FrameContext& f) {
    ReuseParams p = reuseParams(f.in.settings, f.in.frame, f.in.settings.render.seed, f.lg.width, f.lg.height, f.scale);
    p.wholeWidth = f.wholeWidth;
    p.originX = f.originX;
    p.originY = f.originY;
    if (f.texels) p.visible = f.texels->visible();
    return p;
}

/// What a CPU pass reads and writes: its input reservoirs, its output (the
/// same vector for a pass that works in place) and, for traceShadowRays, Lr.
struct CpuBuffers {
    const std::vector<StoredReservoir>* in = nullptr;
    std::vector<StoredReservoir>* out = nullptr;
    std::vector<Vec3>* Lr = nullptr;
    const std::vector<Vec3>* texelLr = nullptr;  ///< particle_restir's pixels: the texels' Lr (their reservoirs are `in`)
};

/// One CPU pass's bridge, made per texel on the thread that runs it.
template <ShadingModel SM, Primitive P, bool Count>
class CpuBridge {
public:
    using Rng = accretion::Rng;

    /// A CPU pass's offers (scratch.offers, cleared): each with its domain
    /// for basic_visibility, combined by combineOffers.
    class Offers {
    public:
        explicit Offers(CpuBridge& b) : b_(b) { b_.scratch_.offers.clear(); }
        void addCurrent(const StoredReservoir& r, const GBufferTexel& g) {
            // With temporal reuse as well, a temporal output also holds samples
            // that passed the previous frame's test, not this pixel's: treating
            // it as tested here is then an approximation (measured by
            // `accretion bias`); exact with temporal off.
            const FrameContext& f = b_.f_;
            b_.scratch_.offers.push_back({r, {accretion::shadingPoint(g, f.in.particles), &f.L, f.rs.candidate_visibility, &f.in.bvh}});
        }
        void addHistory(const StoredReservoir& r, std::size_t q) {
            // The previous frame's visibility needs the previous frame's BVH
            // (kept by the frame renderer when basic_visibility asks for it).
            const FrameContext& f = b_.f_;
            const Restir::History& h = *f.prev;
            b_.scratch_.offers.push_back({r, {accretion::shadingPoint(h.gbuffer.texels[q], h.particles), &h.lights,
                                              f.rs.candidate_visibility || f.rs.visibility_reuse,
                                              f.in.previousBvh ? f.in.previousBvh : &f.in.bvh}});
        }
        StoredReservoir combine(Rng& rng) { return combineOffers<SM, P, Count>(b_.scratch_, b_.f_, rng, b_.c_, *b_.rec_); }

    private:
        CpuBridge& b_;
    };

    CpuBridge(const FrameContext& f, const ReuseParams& p, PassCounters* pc, const CpuBuffers& io, LightingCounters& c,
              Scratch& scratch)
        : f_(f), p_(p), pc_(pc), io_(io), c_(c), scratch_(scratch) {}

    const ReuseParams& params() const { return p_; }
    const GBufferTexel& texel(std::size_t px) const { return f_.lg.texels[px]; }
    const StoredReservoir& input(std::size_t px) const { return (*io_.in)[px]; }
    void output(std::size_t px, const StoredReservoir& r) { (*io_.out)[px] = r; }
    void keep(std::size_t px, const StoredReservoir& r) { (*io_.out)[px] = f_.codec.roundTrip(r); }
    bool reject(std::size_t px) { return f_.reject(px, c_); }
    Recorder<Count>& recorder(std::size_t px, const GBufferTexel& g) {
        rec_.emplace(restir::recorder<Count>(pc_, px));
        recordHit(*rec_, f_, g);
        return *rec_;
    }
    std::uint32_t reservoirBytes() const { return f_.codec.bytes(); }
    void reuse(ReuseOutcome o) {
        if (counted_) c_.reuse.add(o);
    }
    void historyCapped() { c_.reuse.mCapped += counted_; }
    void countReuse(bool counted) { counted_ = counted; }
    template <std::uint32_t N>
    Offers offers() { return Offers(*this); }

    bool historyHas(std::uint32_t j) const { return j < f_.prev->particles.size(); }
    const Vec3& historyPosition(std::uint32_t j) const { return f_.prev->particles.position[j]; }
    const Camera& historyCamera() const { return f_.prev->camera; }
    const GBufferTexel& historyTexel(std::size_t q) const { return f_.prev->gbuffer.texels[q]; }
    const StoredReservoir& historyReservoir(std::size_t q) const { return f_.prev->reservoirs[q]; }

    ShadingPoint shadingPoint(const GBufferTexel& g) const { return accretion::shadingPoint(g, f_.in.particles); }
    float targetPdf(const ShadingPoint& sp, std::uint32_t i) {
        ++c_.lightTerms;
        return f_.L.template targetPdf<SM>(sp, i);
    }
    bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const { return f_.L.template term<SM>(sp, i, t); }
    void countLightTerm() { ++c_.lightTerms; }
    std::uint32_t clusterOf(std::uint32_t i) const { return f_.in.bvh.clusterOf(i); }
    bool shadows() const { return f_.shadows; }
    bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t, Recorder<Count>& rec) {
        return countedShadowRay<P>(f_.in.bvh, f_.vis, f_.L, sp, i, t, c_, rec);
    }
    void occluded() { ++c_.shadowOccluded; }
    bool dropOccludedCandidates() const { return f_.rs.candidate_visibility && f_.shadows; }
    bool visibilityReuse() const { return f_.rs.visibility_reuse; }
    void writeLr(std::size_t px, const Vec3& Lr) { (*io_.Lr)[px] = Lr; }

    // particle_restir (particle_restir_passes.h).
    bool historyTexelOf(std::uint32_t j, std::uint32_t sub, std::size_t& q) const {
        const std::vector<std::uint32_t>& slots = f_.prev->slotOf;
        if (j >= slots.size() || slots[j] == kNoSlot) return false;
        q = std::size_t(slots[j]) * p_.texelsPerParticle() + sub;
        return true;
    }
    const GBufferTexel& pixel(std::size_t px) const { return f_.lg.texels[px]; }
    std::uint32_t slotOf(std::uint32_t j) const { return f_.texels->slotOf[j]; }
    Vec2 pixelUv(const GBufferTexel& g) const {
        return billboardUv(g.local, f_.in.particles.radius[g.particle], f_.in.bvh.frame(g.particle));
    }
    const GBufferTexel& gridTexel(std::size_t q) const { return f_.texels->grid.texels[q]; }
    const StoredReservoir& gridReservoir(std::size_t q) const { return (*io_.in)[q]; }
    const Vec3& gridLr(std::size_t q) const { return (*io_.texelLr)[q]; }
    const Vec3& historyLr(std::size_t q) const { return f_.prev->texelLr[q]; }
    void writePixelLr(std::size_t px, const Vec3& Lr) { (*io_.Lr)[px] = Lr; }

private:
    const FrameContext& f_;
    const ReuseParams& p_;
    PassCounters* pc_;
    const CpuBuffers& io_;
    LightingCounters& c_;
    Scratch& scratch_;
    std::optional<Recorder<Count>> rec_;
    bool counted_ = true;  ///< this texel's reuse counts (FrameContext::counted)
};

/// Runs body(bridge, px, x, y) over the lighting grid (forEachPixel's tiles),
/// each texel with a bridge of its thread's counters and scratch.
template <ShadingModel SM, Primitive P, bool Count, class Body>
LightingCounters forEachTexel(const FrameContext& f, Pass pass, const CpuBuffers& io, Body&& body) {
    const ReuseParams p = reuseParams(f);
    PassCounters* pc = passCounters<Count>(f, pass);
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t x, std::uint32_t y, LightingCounters& c, Scratch& s) {
        CpuBridge<SM, P, Count> b(f, p, pc, io, c, s);
        b.countReuse(f.counted.contains(x, y));
        body(b, px, x, y);
    });
}

}  // namespace accretion::restir
