#pragma once
// particle_split: seed 004's hybrid compute (docs/MODEL.md section 4b,
// docs/designs.md). Particle-to-particle lighting in compute with a spatial
// acceleration structure, ray tracing for visibility alone, lit per
// particle, not per pixel: on the texels of the visible particles'
// billboards (particle_texels.h, particle_restir's grid), each texel
//
//   Lr = sum over the near lights N of f I G V          (every one, exactly)
//      + 1/S sum over S far draws y of f I G V / p(y)   (the light tree, N's
//                                                        ball taken out)
//
// (with particle_split.candidates C > 1 each far draw is the one kept by
// RIS among C, p_hat the unshadowed term: f I G V sum(p_hat / p) / (C p_hat))
//
// N is the particle's particle_split.near lights nearest to its centre c
// other than itself, found on the light tree (nearestLights: a pruned
// search, no rays), shared by its texels. The far draws descend the light
// tree at the texel's point with FarImportance: a node wholly inside the
// ball of N (every light below it is nearer c than the farthest of N, so
// in N) gets no draw; a draw that still lands on a light of N (from a node
// that straddles the ball) adds nothing. Every far light keeps its tree
// pdf, so the far sum is unbiased for the lights outside N, and the texel's
// Lr is unbiased for the light at the texel. With particle_split.history h
// a texel's Lr is (1 - h) x this frame's + h x its own last frame's (the
// same texel of the same particle, by id); with particle_split.history_of
// far only its far mean is so averaged (kept in a buffer of its own), and
// the near sum is this frame's; with particle_split.history_start mean the
// weight of this frame's is max(1 - h, 1/n), n the frames the texel has
// been seen (its age, kept beside it): a running mean, then the
// exponential average. With particle_split.far_new F a texel without
// history (its particle not in last frame's view) draws F far rays, not S,
// and the running mean counts its age in far rays: that first frame
// weighs F / S frames. With particle_split.far_prior P (and history_of
// far) such a texel's far mean starts as the mean of its near lights' far
// means of last frame (those in view then), worth P far rays: a particle
// new to the view starts from its world-space neighbours' far light. With
// particle_split.far_share every texel's Lr so blends its far mean with
// its neighbours' (its history keeping its own). With particle_split.far_handoff
// a texel's far history follows its particle's near set: a light near
// now but not last frame (its far light in the history) is taken out of
// the history at this frame's near term, and one near last frame but not
// now (missing from the history) put in at last frame's near term, kept
// per texel. Without it the history and the near sum both hold a light
// that joined the near set (at its far terms then and its near term now)
// and neither holds one that left; on the rotating disk these do not
// cancel: the frames come out darker (docs/designs.md). The pixels interpolate their particle's texels:
// biased by the light at the texels, not at the pixel.
//
// The bodies are the CPU's (src/render/particle_split/) and the twin's
// (src/twin/), over a bridge B:
//
//   const SplitParams& params()
//   findNearLights:   std::uint32_t particleOfSlot(v); Vec3 particlePosition(j); std::uint64_t lightPath(j)
//                     (LightTree::paths);
//                     const LightTreeView& tree(); void writeNear(v, light, count, radius2)
//   shadeSplitTexels: GBufferTexel texel(q); ShadingPoint shadingPoint(g);
//                     SplitRay splitRay(q, r)  texel q's ray r: traceSplitRay's (the CPU
//                                             calls it; the twin's rays ran in a launch of
//                                             their own, one a thread; r past near + far:
//                                             far_new's, for a texel without history)
//                     std::uint32_t nearLight(v, m)   slot v's near light m (kNoNearLight past its count)
//                     std::uint32_t nearLights(v, light) (all of them; returns the count); float nearRadius2(v)
//                     LightSample sampleFar(sp, rng, importance)  the tree's descent (counted)
//                     bool term(sp, i, t)     light i's term f I G in the frame's shading model (counted)
//                     bool shadows(); bool visible(sp, i, t)  a shadow ray (traced, counted)
//                     void reject(q)          a far ray's non-finite value rejected (render.nonfinite)
//                     bool historyTexelOf(j, sub, q); Vec3 historyLr(q); void writeTexelLr(q, Lr)
//                     Vec3 historyFar(q); void writeTexelFar(q, far)  (history_of far)
//                     std::uint32_t historyNearLights(v, light)  last frame's slot v's near lights (far_handoff)
//                     Vec3 historyNearValue(q, m); void writeTexelNear(q, m, value)  a texel's near term m, last frame's and this one's
//                     std::uint32_t historyAge(q); void writeTexelAge(q, n)  (history_start mean)
//   shadePixels:      GBufferTexel pixel(px); std::uint32_t slotOf(j); Vec2 pixelUv(g);
//                     Vec3 texelLr(q); void writePixelLr(px, Lr)
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/light_tree_view.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/render/particle_texels.h"

namespace accretion::psplit {

/// The most near lights a particle sums (particle_split.near).
inline constexpr std::uint32_t kMaxNear = 64;
inline constexpr std::uint32_t kNoNearLight = 0xffffffffu;

/// What the passes read of the settings and the frame.
struct SplitParams {
    std::uint32_t nearCount = 16;   ///< particle_split.near: k
    std::uint32_t farSamples = 8;   ///< particle_split.far: S
    std::uint32_t farNew = 0;       ///< particle_split.far_new: far draws of a texel without history (0: S)
    std::uint32_t farPrior = 0;     ///< particle_split.far_prior: far rays' worth of a new texel's near lights' far means (0: none)
    std::uint32_t farShare = 0;     ///< particle_split.far_share: far rays' worth of every texel's near lights' far means in its Lr (0: none)
    std::uint32_t candidates = 1;   ///< particle_split.candidates: C far draws resampled into each far shadow ray
    std::uint32_t side = 1;         ///< particle_split.texels: texels per billboard side
    float history = 0.0f;           ///< particle_split.history
    bool historyOfFar = false;      ///< particle_split.history_of far: the history averages the far mean alone
    bool historyMean = false;       ///< particle_split.history_start mean: a running mean over the texel's age first
    bool farHandoff = false;        ///< particle_split.far_handoff: the far history follows the near set's changes
    bool discardNonFinite = false;  ///< render.nonfinite discard: a non-finite far draw is not counted (else it counts as 0)
    std::uint32_t visible = 0;      ///< the frame's visible particles (slots)
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
    ACC_HD std::uint32_t texelsPerParticle() const { return side * side; }
    /// far_handoff in effect: the texels' near terms and the near sets are kept for the next frame.
    ACC_HD bool keepsNearTerms() const { return history > 0.0f && historyOfFar && farHandoff; }
};

/// The frame's parameters from the settings (the CPU's and the twin's).
inline SplitParams splitParams(const Settings& s, std::uint32_t visible, std::uint32_t frame, std::uint64_t seed) {
    SplitParams p;
    p.nearCount = s.particle_split.near;
    p.farSamples = s.particle_split.far;
    p.farNew = s.particle_split.far_new;
    p.farPrior = s.particle_split.far_prior;
    p.farShare = s.particle_split.far_share;
    p.candidates = s.particle_split.candidates;
    p.side = s.particle_split.texels;
    p.history = float(s.particle_split.history);
    p.historyOfFar = s.particle_split.history_of == HistoryOf::far;
    p.historyMean = s.particle_split.history_start == HistoryStart::mean;
    p.farHandoff = s.particle_split.far_handoff;
    p.discardNonFinite = s.render.nonfinite == NonFinitePolicy::discard;
    p.visible = visible;
    p.frame = frame;
    p.seed = seed;
    return p;
}

/// Where the frame's texels lie on their billboards (particle_split.texel_point).
inline TexelPointRule texelPoints(const Settings& s, std::uint32_t frame, std::uint64_t seed) {
    TexelPointRule r;
    r.mode = s.particle_split.texel_point;
    r.disc = s.geometry.alpha == AlphaMode::disc;
    r.frame = frame;
    r.seed = seed;
    return r;
}

/// A step of nearestLights' search, as its visitor sees it: an inner node
/// read (and its two children's bounds), a leaf read, or one swap of the
/// heap of the k best (sifting an entry up or down, or sorting it at the end).
enum class SearchStep : std::uint8_t { inner, leaf, sift };

/// nearestLights' visitor by default: nothing (the passes' bodies; the CPU's
/// counting runs the search again with one that records each step).
struct NoSearchVisit {
    ACC_HD void operator()(SearchStep) const {}
};

/// The min(k, kMaxNear) lights nearest to x other than `self` on the light
/// tree's nodes, nearest first (ties: the smaller index first), with their
/// squared distances (each leaf's centre to x, as FarImportance measures
/// them). A depth-first search, the nearer child first, pruned by the k-th
/// distance so far: first below the smallest node on self's path from the
/// root (`selfPath`, LightTree::paths) that holds more than k lights, whose
/// lights are its spatial neighbours, so that the search from the root
/// starts with a tight k-th distance and skips that subtree (x is self's
/// position). Returns how many (fewer where the tree holds fewer).
/// visit(step) is called on each node the search reads (not on the pruned
/// ones) and on each swap of its heap.
template <class Visit = NoSearchVisit>
ACC_HD inline std::uint32_t nearestLights(const LightTreeView& tree, const Vec3& x, std::uint32_t self, std::uint64_t selfPath,
                                          std::uint32_t k, std::uint32_t* light, float* d2, Visit visit = {}) {
    if (k > kMaxNear) k = kMaxNear;
    if (tree.nodeCount == 0 || k == 0) return 0;
    // A max-heap of the best so far on (d2, light).
    std::uint32_t found = 0;
    const auto worse = [&](std::uint32_t a, std::uint32_t b) {  // entry a is farther than entry b
        return d2[a] > d2[b] || (d2[a] == d2[b] && light[a] > light[b]);
    };
    const auto swapEntries = [&](std::uint32_t a, std::uint32_t b) {
        visit(SearchStep::sift);
        const float t = d2[a];
        d2[a] = d2[b];
        d2[b] = t;
        const std::uint32_t u = light[a];
        light[a] = light[b];
        light[b] = u;
    };
    const auto siftDown = [&](std::uint32_t at, std::uint32_t n) {
        for (;;) {
            const std::uint32_t l = 2 * at + 1, r = l + 1;
            std::uint32_t top = at;
            if (l < n && worse(l, top)) top = l;
            if (r < n && worse(r, top)) top = r;
            if (top == at) return;
            swapEntries(at, top);
            at = top;
        }
    };
    const auto sphereBound = [&](const LightTreeNode& n) {
        const Vec3 delta = n.center - x;
        const float d = sqrtf(delta.x * delta.x + delta.y * delta.y + delta.z * delta.z) - n.radius;
        return d > 0.0f ? d * d : 0.0f;
    };
    struct Pending {
        std::uint32_t node;
        float bound;
    };
    Pending stack[2 * 64 + 2];  // the tree is at most 64 deep (LightTree's build)
    std::uint32_t top = 0;
    std::uint32_t seed = 0;
    for (std::uint32_t depth = 0; depth < 64 && tree.nodes[seed].count > 1; ++depth) {
        const std::uint32_t next = tree.nodes[seed].child + std::uint32_t((selfPath >> depth) & 1u);
        if (tree.nodes[next].count <= k) break;
        seed = next;
    }
    stack[top++] = {0u, sphereBound(tree.nodes[0])};
    if (seed != 0) stack[top++] = {seed, 0.0f};  // popped first
    bool seedSearched = false;
    while (top > 0) {
        const Pending p = stack[--top];
        if (seed != 0 && p.node == seed) {  // the second time, reached from the root: searched already
            if (seedSearched) continue;
            seedSearched = true;
        }
        if (found == k && !(p.bound <= d2[0])) continue;
        const LightTreeNode& n = tree.nodes[p.node];
        visit(n.count == 1 ? SearchStep::leaf : SearchStep::inner);
        if (n.count == 1) {
            if (n.child == self) continue;
            const Vec3 delta = n.center - x;
            const float dd = delta.x * delta.x + delta.y * delta.y + delta.z * delta.z;
            if (found < k) {  // sift the new entry up
                std::uint32_t at = found++;
                d2[at] = dd;
                light[at] = n.child;
                while (at > 0 && worse(at, (at - 1) / 2)) {
                    swapEntries(at, (at - 1) / 2);
                    at = (at - 1) / 2;
                }
            } else if (dd < d2[0] || (dd == d2[0] && n.child < light[0])) {
                d2[0] = dd;
                light[0] = n.child;
                siftDown(0, found);
            }
            continue;
        }
        const Pending a{n.child, sphereBound(tree.nodes[n.child])}, b{n.child + 1, sphereBound(tree.nodes[n.child + 1])};
        stack[top++] = a.bound <= b.bound ? b : a;  // pushed far first: the near one is popped first
        stack[top++] = a.bound <= b.bound ? a : b;
    }
    // Nearest first: the heap sorted in place.
    for (std::uint32_t n = found; n > 1; --n) {
        swapEntries(0, n - 1);
        siftDown(0, n - 1);
    }
    return found;
}

/// The ball of the near lights: every light nearer `centre` than
/// sqrt(radius2) is one of them (nearestLights kept the nearest). `inner2`
/// is radius2 less a margin for the rounding of the node's bounds.
ACC_HD inline float innerRadius2(float radius2) { return radius2 * (1.0f - 2e-3f); }

/// The far draws' importance of a node (LightTreeView::sample's
/// importanceOf): 0 for a node wholly inside the near lights' ball, else
/// the tree's own descent importance at the receiver.
struct FarImportance {
    Vec3 centre{0.0f};
    float inner2 = 0.0f;
    ACC_HD bool inside(const LightTreeNode& n) const {
        const Vec3 d = n.center - centre;
        const float dd = d.x * d.x + d.y * d.y + d.z * d.z;
        if (n.count == 1) return dd < inner2;
        const float reach = sqrtf(dd) + n.radius;
        return reach * reach < inner2;
    }
    ACC_HD float operator()(const LightTreeView& tree, std::uint32_t n, const ShadingPoint& sp) const {
        return inside(tree.nodes[n]) ? 0.0f : tree.descentImportance(n, tree.nodes[n].power, sp);
    }
};

/// Whether light i is one of the `count` near lights.
ACC_HD inline bool isNear(const std::uint32_t* light, std::uint32_t count, std::uint32_t i) {
    for (std::uint32_t m = 0; m < count; ++m)
        if (light[m] == i) return true;
    return false;
}

/// findNearLights at slot v: its particle's near lights and their ball.
template <class B>
ACC_HD_BODY void findNearLightsOf(B& b, std::uint32_t v) {
    const SplitParams& p = b.params();
    const std::uint32_t j = b.particleOfSlot(v);
    std::uint32_t light[kMaxNear];
    float d2[kMaxNear];
    const std::uint32_t n = nearestLights(b.tree(), b.particlePosition(j), j, b.lightPath(j), p.nearCount, light, d2);
    b.writeNear(v, light, n, n > 0 ? d2[n - 1] : 0.0f);
}

/// What one ray of a texel brings: near light r's f I G V, or far draw s's
/// f I G V / p (RIS: f I G V sum(w) / (C p_hat)); `rejected` when that was
/// not finite (render.nonfinite: the value is 0).
struct SplitRay {
    Vec3 value{0.0f};
    std::uint32_t rejected = 0;
};

/// The rays of a texel: params.nearCount near slots, then params.farSamples far draws.
ACC_HD inline std::uint32_t raysPerTexel(const SplitParams& p) { return p.nearCount + p.farSamples; }

/// The far rays a texel without history draws beyond params.farSamples
/// (particle_split.far_new; 0 without a history, where no texel has one).
ACC_HD inline std::uint32_t extraNewRays(const SplitParams& p) {
    return p.history > 0.0f && p.farNew > p.farSamples ? p.farNew - p.farSamples : 0u;
}

/// Whether texel q is drawn particle_split.far_new far rays: a history is
/// kept and the texel's particle was not in last frame's view.
template <class B>
ACC_HD_BODY bool newSplitTexel(B& b, std::size_t q) {
    const SplitParams& p = b.params();
    if (!(p.history > 0.0f)) return false;
    const GBufferTexel g = b.texel(q);
    std::size_t last = 0;
    return g.hit() && !b.historyTexelOf(g.particle, std::uint32_t(q % p.texelsPerParticle()), last);
}

/// shadeSplitTexels' thread of ray r of texel q, of `texels`: the near rays
/// texel by texel (q x nearCount + r), then the far draws texel by texel,
/// then far_new's extra draws of the texels without history, in their order
/// (`newIndex`: texel q's place among them). A warp traces one kind of ray
/// for a few texels, which share their shading point, near lights and tree
/// descents. On the H100 (no RT cores) warps of one ray of 32 texels took
/// 4-19% longer, and OptiX's 2D launch of texels by rays up to 2.7x longer
/// (bench/gpu run.sh split_order).
ACC_HD inline std::size_t splitRayThread(const SplitParams& p, std::size_t texels, std::size_t q, std::uint32_t r,
                                         std::size_t newIndex = 0) {
    const std::uint32_t base = raysPerTexel(p);
    if (r >= base) return texels * base + newIndex * extraNewRays(p) + (r - base);
    return r < p.nearCount ? q * p.nearCount + r : texels * p.nearCount + q * p.farSamples + (r - p.nearCount);
}

/// The texel and ray of shadeSplitTexels' thread L (splitRayThread's
/// inverse); `newTexels`: the texels without history, in order (read only
/// past the texels' own near and far rays, where extraNewRays).
struct SplitRayOfThread {
    std::size_t texel;
    std::uint32_t ray;
};
ACC_HD inline SplitRayOfThread splitRayOfThread(const SplitParams& p, std::size_t texels, std::size_t L,
                                                const std::uint32_t* newTexels = nullptr) {
    const std::uint32_t base = raysPerTexel(p);
    const std::size_t nearThreads = texels * p.nearCount, baseThreads = texels * base;
    if (L < nearThreads) return {L / p.nearCount, std::uint32_t(L % p.nearCount)};
    if (L < baseThreads) return {(L - nearThreads) / p.farSamples, p.nearCount + std::uint32_t((L - nearThreads) % p.farSamples)};
    const std::uint32_t extra = extraNewRays(p);
    return {newTexels[(L - baseThreads) / extra], base + std::uint32_t((L - baseThreads) % extra)};
}

/// Ray r of texel q: for r < nearCount its particle's near light r (none
/// where the particle has fewer), else its far draw r - nearCount, from its
/// own stream (by particle id and texel, so that a texel's rays can run
/// apart and its draws do not depend on its slot).
template <class B>
ACC_HD_BODY SplitRay traceSplitRay(B& b, std::size_t q, std::uint32_t r) {
    const SplitParams& p = b.params();
    SplitRay out;
    const GBufferTexel g = b.texel(q);
    if (!g.hit()) return out;  // the grid's last row's tail
    const std::uint32_t per = p.texelsPerParticle();
    const std::uint32_t slot = std::uint32_t(q / per), sub = std::uint32_t(q % per);
    const ShadingPoint sp = b.shadingPoint(g);
    LightTerm t{};
    if (r < p.nearCount) {  // a near ray reads its own light alone
        const std::uint32_t i = b.nearLight(slot, r);
        if (i != kNoNearLight && b.term(sp, i, t) && (!b.shadows() || b.visible(sp, i, t))) out.value = t.value;
        return out;
    }
    std::uint32_t near[kMaxNear];  // a far ray reads them all: its draws must miss them
    const std::uint32_t k = b.nearLights(slot, near);
    const FarImportance importance{sp.centre, k > 0 ? innerRadius2(b.nearRadius2(slot)) : 0.0f};
    PortableRng rng(std::uint64_t(g.particle) * per + sub, p.frame, RngPass::particleSplit, p.seed, r - p.nearCount + 1);
    // RIS over C far draws (C = 1: the draw itself): the one kept in
    // proportion to w = p_hat / pdf, p_hat the unshadowed term's luminance.
    float wSum = 0.0f, pHat = 0.0f;
    std::uint32_t kept = kNoLightSample;
    for (std::uint32_t c = 0; c < p.candidates; ++c) {
        const LightSample y = b.sampleFar(sp, rng, importance);
        if (!(y.pdf > 0.0f) || isNear(near, k, y.i)) continue;
        LightTerm ty;
        if (!b.term(sp, y.i, ty)) continue;
        const float ph = luminance(ty.value), w = ph / y.pdf;
        if (!(w > 0.0f)) continue;
        wSum += w;
        if (c == 0 || rng.uniform() * wSum < w) {
            kept = y.i;
            pHat = ph;
            t = ty;
        }
    }
    if (kept == kNoLightSample || (b.shadows() && !b.visible(sp, kept, t))) return out;
    const Vec3 v = t.value * (wSum / (float(p.candidates) * pHat));
    if (isFiniteNumber(v.x + v.y + v.z)) out.value = v;
    else out.rejected = 1;
    return out;
}

/// The mean of the far means that texel q's particle's near lights' same
/// texels kept last frame (history_of far; those then in view): its
/// world-space neighbours' far light. False where none was in view.
template <class B>
ACC_HD_BODY bool neighbourFarMean(B& b, std::size_t q, Vec3& mean) {
    const SplitParams& p = b.params();
    std::uint32_t near[kMaxNear];
    const std::uint32_t k = b.nearLights(std::uint32_t(q / p.texelsPerParticle()), near);
    Vec3 sum(0.0f);
    std::uint32_t found = 0;
    for (std::uint32_t m = 0; m < k; ++m) {
        std::size_t hq = 0;
        if (!b.historyTexelOf(near[m], std::uint32_t(q % p.texelsPerParticle()), hq)) continue;
        sum += b.historyFar(hq);
        ++found;
    }
    if (found > 0) mean = sum / float(found);
    return found > 0;
}

/// A texel's age (history_start mean) counts the far rays it has averaged
/// (its frames, where it draws none), held at 2^24 (past any 1 / (1 - h)
/// the settings allow, and exact as a float): this frame's from last
/// frame's, `units` this frame's rays.
inline constexpr std::uint32_t kMaxHistoryAge = 1u << 24;
ACC_HD inline std::uint32_t historyAgeAfter(std::uint32_t last, std::uint32_t units) {
    return last < kMaxHistoryAge - units ? last + units : kMaxHistoryAge;
}

/// shadeSplitTexels at texel q: its rays (b.splitRay: traceSplitRay's)
/// summed in order, the near ones as they are and the far ones' mean (far_new
/// of them without history), and with history the texel's last Lr.
template <class B>
ACC_HD_BODY void sumSplitTexel(B& b, std::size_t q) {
    const SplitParams& p = b.params();
    const GBufferTexel g = b.texel(q);
    const bool history = p.history > 0.0f;
    if (!g.hit()) {
        b.writeTexelLr(q, Vec3(0.0f));
        if (history && p.historyOfFar) b.writeTexelFar(q, Vec3(0.0f));
        if (history && p.historyMean) b.writeTexelAge(q, 0);
        return;
    }
    // The history: last frame's texel of the same particle, and the weight it keeps.
    std::size_t h = 0;
    const bool seen = history && b.historyTexelOf(g.particle, std::uint32_t(q % p.texelsPerParticle()), h);
    const std::uint32_t farRays = p.farSamples + (history && !seen ? extraNewRays(p) : 0u);
    // far_handoff: this frame's near terms are kept for the next frame,
    // and a texel with history reads last frame's near set (by its slot then).
    const bool keepNear = p.keepsNearTerms(), handoff = keepNear && seen;
    std::uint32_t now[kMaxNear], before[kMaxNear], kNow = 0, kBefore = 0;
    if (handoff) {
        kNow = b.nearLights(std::uint32_t(q / p.texelsPerParticle()), now);
        kBefore = b.historyNearLights(std::uint32_t(h / p.texelsPerParticle()), before);
    }
    Vec3 Lr(0.0f), far(0.0f), joined(0.0f);
    for (std::uint32_t r = 0; r < p.nearCount; ++r) {
        const Vec3 v = b.splitRay(q, r).value;
        Lr += v;
        if (keepNear) b.writeTexelNear(q, r, v);
        if (handoff && r < kNow && !isNear(before, kBefore, now[r])) joined += v;  // far in the history, near now
    }
    std::uint32_t counted = farRays;
    for (std::uint32_t s = 0; s < farRays; ++s) {
        const SplitRay ray = b.splitRay(q, p.nearCount + s);
        if (ray.rejected) {
            b.reject(q);
            if (p.discardNonFinite) --counted;
        }
        far += ray.value;
    }
    // far_prior: a texel without history starts from its neighbours' far
    // light (neighbourFarMean), worth farPrior far rays.
    const std::uint32_t units = farRays > 0 ? farRays : 1u;
    Vec3 prior(0.0f);
    std::uint32_t priorUnits = 0;
    if (history && p.historyOfFar && !seen && p.farPrior > 0 && neighbourFarMean(b, q, prior)) priorUnits = p.farPrior;
    float keep = p.history;
    std::uint32_t age = 0;
    if (history && p.historyMean) {  // this frame weighs units / age: 1 / n after n frames of S far rays
        age = seen ? historyAgeAfter(b.historyAge(h), units) : units + priorUnits;
        keep = fminf(p.history, 1.0f - float(units) / float(age));
        b.writeTexelAge(q, age);
    }
    if (history && p.historyOfFar) {
        Vec3 farMean = counted > 0 ? far / float(counted) : Vec3(0.0f);
        if (seen) {
            Vec3 last = b.historyFar(h);
            if (handoff) {  // the history as if its frames had taken this frame's near set out
                last -= joined;
                for (std::uint32_t m = 0; m < kBefore; ++m)
                    if (!isNear(now, kNow, before[m])) last += b.historyNearValue(h, m);  // near in the history, far now: its last term
            }
            farMean = (1.0f - keep) * farMean + keep * last;
        }
        else if (priorUnits > 0) {
            const float own = float(units) / float(units + priorUnits);
            farMean = own * farMean + (1.0f - own) * prior;
        }
        b.writeTexelFar(q, farMean);
        // far_share: the texel shows its far mean blended with its
        // neighbours' (the history keeps its own), each weighed by the far
        // rays it stands for: its own by its age (or the exponential
        // average's S (1 + h) / (1 - h), whichever is less), theirs as farShare.
        Vec3 neighbours(0.0f);
        if (p.farShare > 0 && neighbourFarMean(b, q, neighbours)) {
            const float steady = float(units) * (1.0f + p.history) / (1.0f - p.history);
            const float own = p.historyMean ? fminf(float(age), steady) : steady;
            const float w = own / (own + float(p.farShare));
            farMean = w * farMean + (1.0f - w) * neighbours;
        }
        b.writeTexelLr(q, Lr + farMean);
        return;
    }
    if (counted > 0) Lr += far / float(counted);
    if (seen) Lr = (1.0f - keep) * Lr + keep * b.historyLr(h);
    b.writeTexelLr(q, Lr);
}

/// shadeParticlePixels at image pixel px: its particle's texels' Lr,
/// bilinear at its billboard uv (texelStencil).
template <class B>
ACC_HD_BODY void interpolateSplitPixel(B& b, std::size_t px) {
    const SplitParams& p = b.params();
    const GBufferTexel g = b.pixel(px);
    Vec3 Lr(0.0f);
    if (g.hit()) {
        std::size_t q[4];
        float w[4];
        const std::uint32_t n = texelStencil(b.pixelUv(g), p.side, 1, std::size_t(b.slotOf(g.particle)) * p.texelsPerParticle(), q, w);
        for (std::uint32_t c = 0; c < n; ++c) Lr += w[c] * b.texelLr(q[c]);
    }
    b.writePixelLr(px, Lr);
}

}  // namespace accretion::psplit
