#include "accretion/lighting/restir.h"

#include <cmath>

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "accretion/core/error.h"
#include "accretion/core/rng.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/visibility.h"

namespace accretion {

/// The previous frame as temporal reuse sees it.
struct Restir::History {
    GBuffer gbuffer;                        ///< lighting-resolution G-buffer
    Particles particles;                    ///< previous positions / emission / albedo
    LightArrays lights;                     ///< views of `particles`
    Camera camera;
    std::vector<StoredReservoir> reservoirs;
};

namespace {

/// The domain of a reservoir: the receiver and the lights its p_hat used,
/// and whether its samples passed a visibility test (then its support is
/// that of p_hat x V, and basic_visibility must test V to count it).
struct Domain {
    ShadingPoint sp;
    const LightArrays* lights;
    bool visibilityTested = false;
    const ParticleBvh* bvh = nullptr;  ///< the geometry of the domain's frame (visibility tests)
};

/// A reservoir offered for resampling at the current pixel.
struct Offer {
    StoredReservoir r;
    Domain domain;
};

/// Neighbour rejection shared by the temporal and spatial passes.
bool similar(const GBufferTexel& a, const GBufferTexel& b, const RestirSettings& rs) {
    if (!b.hit()) return false;
    if (glm::dot(a.normal, b.normal) < float(rs.normal_threshold)) return false;
    return std::fabs(a.depth - b.depth) <= float(rs.depth_threshold) * a.depth;
}

/// Combines the canonical reservoir (offers[0], in the current domain) with
/// the others. none: W = w_sum / (M_total p_hat(y)); basic: the sum of M runs
/// only over domains whose p_hat of y is non-zero (and that see y, with
/// basic_visibility); pairwise: each neighbour forms a two-strategy balance
/// heuristic with the canonical, whose confidence is split over the k pairs
/// (weights sum to 1 for every y; equal p_hat gives M_i / M_total).
template <ShadingModel SM, Primitive P, bool Count>
StoredReservoir combine(const Offer* offers, std::uint32_t n, const LightArrays& L, const RestirSettings& rs,
                        const VisibilityOptions& vis, bool shadows, Rng& rng, LightingCounters& c, Recorder<Count>& rec) {
    const Offer& can = offers[0];
    const ShadingPoint& sp = can.domain.sp;
    if (n == 1) return can.r;
    double Mtotal = 0.0;
    for (std::uint32_t i = 0; i < n; ++i) Mtotal += offers[i].r.M;

    // p_hat at the current pixel of every offered sample.
    float pc[1 + 64];
    pc[0] = can.r.W > 0.0f ? can.r.p_hat : 0.0f;
    for (std::uint32_t i = 1; i < n; ++i) {
        pc[i] = offers[i].r.W > 0.0f ? L.targetPdf<SM>(sp, offers[i].r.y) : 0.0f;
        ++c.lightTerms;
    }

    Reservoir out;
    if (rs.bias_correction == BiasCorrection::pairwise) {
        const double k = n - 1;
        const double Mc = can.r.M;
        for (std::uint32_t i = 0; i < n; ++i) {
            const StoredReservoir& r = offers[i].r;
            double m = 0.0;
            if (r.W > 0.0f && pc[i] > 0.0f) {
                if (i == 0) {
                    for (std::uint32_t j = 1; j < n; ++j) {
                        const double Mj = offers[j].r.M;
                        const double pj = offers[j].domain.lights->targetPdf<SM>(offers[j].domain.sp, r.y);
                        ++c.lightTerms;
                        const double a = Mj * pj, b = Mc / k * pc[0];
                        m += (Mj + Mc / k) / Mtotal * (a + b > 0.0 ? b / (a + b) : 0.0);
                    }
                } else {
                    const double a = double(r.M) * r.p_hat, b = Mc / k * pc[i];
                    m = (r.M + Mc / k) / Mtotal * (a + b > 0.0 ? a / (a + b) : 0.0);
                }
            }
            const float w = static_cast<float>(m * double(pc[i]) * double(r.W));
            out.merge(r.y, w, pc[i], r.M, rng.uniform());
        }
        StoredReservoir res;
        res.M = static_cast<std::uint32_t>(std::min(Mtotal, 4294967295.0));
        if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
        res.y = out.y;
        res.p_hat = out.p_hat;
        res.W = out.w_sum / out.p_hat;
        return res;
    }

    std::uint32_t chosen = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        const StoredReservoir& r = offers[i].r;
        const float w = pc[i] * r.W * float(r.M);
        if (out.merge(r.y, w, pc[i], r.M, rng.uniform())) chosen = i;
    }
    StoredReservoir res;
    res.M = static_cast<std::uint32_t>(std::min(Mtotal, 4294967295.0));
    if (out.y == kNoLight || !(out.p_hat > 0.0f)) return res;
    double Z = Mtotal;
    if (rs.bias_correction == BiasCorrection::basic) {
        Z = offers[chosen].r.M;  // the domain that produced y can produce it
        for (std::uint32_t i = 0; i < n; ++i) {
            if (i == chosen) continue;
            const Domain& d = offers[i].domain;
            LightTerm t;
            ++c.lightTerms;
            if (!d.lights->term<SM>(d.sp, out.y, t) || !(luminance(t.value) > 0.0f)) continue;
            if (rs.basic_visibility && d.visibilityTested && shadows) {
                ++c.shadowRays;
                RayCounters rc;
                const PackedLight& l = d.lights->packed[out.y];
                const bool seen = visible<P>(*d.bvh, vis, d.sp, out.y, l.position, l.radius, t, rec.rayCounters(rc));
                rec.ray(rc);
                if (!seen) {
                    ++c.shadowOccluded;
                    continue;
                }
            }
            Z += offers[i].r.M;
        }
    }
    res.y = out.y;
    res.p_hat = out.p_hat;
    res.W = static_cast<float>(double(out.w_sum) / (Z * double(out.p_hat)));
    return res;
}

/// Runs body(px, x, y, counters) over the pixels of a w x h grid in 8x8 tiles.
template <class Body>
LightingCounters forEachPixel(std::uint32_t w, std::uint32_t h, Body&& body) {
    tbb::enumerable_thread_specific<LightingCounters> counters;
    tbb::parallel_for(tbb::blocked_range2d<std::uint32_t>(0, h, 8, 0, w, 8), [&](const auto& r) {
        LightingCounters& c = counters.local();
        for (std::uint32_t y = r.rows().begin(); y != r.rows().end(); ++y)
            for (std::uint32_t x = r.cols().begin(); x != r.cols().end(); ++x) body(std::size_t(y) * w + x, x, y, c);
    });
    LightingCounters total;
    for (const auto& c : counters) total += c;
    return total;
}

struct FrameContext {
    const RestirInputs& in;
    const RestirSettings& rs;
    const ReservoirCodec& codec;
    const GBuffer& lg;          ///< lighting-resolution G-buffer
    const LightArrays& L;
    const Restir::History* prev;
    float scale;                ///< lighting / image resolution
    VisibilityOptions vis;      ///< render.visibility_rule
    bool shadows;               ///< shading.visibility: trace shadow rays (off: V = 1)
    FrameCounters* counters;    ///< counting mode: per-pass thread records
    std::uint32_t* rejected;    ///< per lighting texel: non-finite values rejected (render.nonfinite)

    /// A reservoir whose weights overflowed or went NaN: counted at px;
    /// zero_sample keeps its M with W = 0, discard empties it.
    StoredReservoir sanitize(StoredReservoir r, std::size_t px, LightingCounters& c) const {
        if (std::isfinite(r.W) && std::isfinite(r.p_hat)) return r;
        if (reject(px, c)) return StoredReservoir{};
        return StoredReservoir{kNoLight, 0.0f, r.M, 0.0f};
    }
    /// Count a non-finite value at px; true if the policy discards the reservoir.
    bool reject(std::size_t px, LightingCounters& c) const {
        ++c.nonFinite;
        ++rejected[px];
        return in.settings.render.nonfinite == NonFinitePolicy::discard;
    }
};

/// The counters of a pass about to run (counting mode), else null.
template <bool Count>
PassCounters* passCounters(const FrameContext& f, std::string_view name) {
    if constexpr (Count) return &f.counters->add(name, f.lg.width, f.lg.height);
    return nullptr;
}

template <bool Count>
Recorder<Count> recorder(PassCounters* pc, std::size_t px) {
    if constexpr (Count) return Recorder<true>(&pc->threads[px]);
    else return Recorder<false>(nullptr);
}

/// The branch key of a lighting-grid texel (counting mode).
template <bool Count>
void recordHit(Recorder<Count>& rec, const FrameContext& f, const GBufferTexel& g) {
    rec.read(gpu_layout::kGBufferTexel);
    if constexpr (Count)
        if (g.hit()) rec.shade(true, f.in.particles.type[g.particle], f.in.bvh.clusterOf(g.particle));
}

template <ShadingModel SM, Primitive P, bool Power, bool Count>
LightingCounters generateCandidates(const FrameContext& f, std::vector<StoredReservoir>& out) {
    const std::uint32_t Mc = f.in.settings.render.candidates;
    PassCounters* pc = passCounters<Count>(f, pass::generateCandidates);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = StoredReservoir{};
        if (!g.hit()) return;
        rec.trip(Mc);
        rec.read(Mc * (gpu_layout::kParticleRecord + (Power ? gpu_layout::kAliasEntry : 0u)));
        rec.write(R);
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        Rng rng(px, f.in.frame, RngPass::restirCandidates, f.in.settings.render.seed);
        Reservoir r;
        bool discard = false;
        for (std::uint32_t m = 0; m < Mc; ++m) {
            const LightSample x = sampleSource<Power>(f.L, f.in.powerTable, rng);
            float p_hat = f.L.targetPdf<SM>(sp, x.i);
            float w = p_hat / x.pdf;
            ++c.lightTerms;
            if (!std::isfinite(w) || !std::isfinite(p_hat)) {  // render.nonfinite: a zero candidate, or no reservoir
                discard = f.reject(px, c) || discard;
                w = p_hat = 0.0f;
            }
            r.update(x.i, w, p_hat, rng.uniform());
        }
        r.finalize();
        if (!std::isfinite(r.w_sum) || !std::isfinite(r.W)) {  // finite weights whose sum overflowed
            discard = f.reject(px, c) || discard;
            r.W = 0.0f;
        }
        if (discard) return;  // out[px] stays empty
        if (f.rs.candidate_visibility && f.shadows && r.W > 0.0f) {
            // Bitterli et al. 2020, Alg. 5: drop an occluded candidate before reuse.
            LightTerm t;
            if (f.L.term<SM>(sp, r.y, t)) {
                ++c.shadowRays;
                RayCounters rc;
                const bool seen = visible<P>(f.in.bvh, f.vis, sp, r.y, f.L.packed[r.y].position, f.L.packed[r.y].radius, t, rec.rayCounters(rc));
                rec.ray(rc);
                if (!seen) {
                    ++c.shadowOccluded;
                    r.W = 0.0f;
                }
            }
        }
        StoredReservoir s;
        s.M = r.M;
        if (r.W > 0.0f) {
            s.y = r.y;
            s.W = r.W;
            s.p_hat = r.p_hat;
        }
        out[px] = f.codec.roundTrip(s);
    });
}

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters temporalResampling(const FrameContext& f, const std::vector<StoredReservoir>& cur,
                                    std::vector<StoredReservoir>& out) {
    const Restir::History& h = *f.prev;
    const Particles& particles = f.in.particles;
    PassCounters* pc = passCounters<Count>(f, pass::temporalResampling);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = cur[px];
        if (!g.hit()) return;
        rec.trip();
        rec.read(R + 2 * gpu_layout::kParticleRecord);  // the reservoir, the particle now and before
        rec.write(R);
        // Where this surface point was: moved back by its particle's motion,
        // projected with the previous camera onto the previous lighting grid.
        const std::uint32_t j = g.particle;
        if (j >= h.particles.size()) {
            ++c.reuseRejected;
            return;
        }
        const Vec3 xPrev = h.particles.position[j] + g.local;  // frame-independent: relative to the particle
        float fx, fy, depth;
        bool ok = h.camera.project(xPrev, fx, fy, depth);
        const float lx = fx * f.scale, ly = fy * f.scale;
        ok = ok && lx >= 0.0f && ly >= 0.0f && lx < float(h.gbuffer.width) && ly < float(h.gbuffer.height);
        std::size_t q = 0;
        if (ok) {
            rec.read(gpu_layout::kGBufferTexel);
            q = std::size_t(ly) * h.gbuffer.width + std::size_t(lx);
            const GBufferTexel& gp = h.gbuffer.texels[q];
            ok = gp.particle == j && glm::dot(gp.normal, g.normal) >= float(f.rs.normal_threshold) &&
                 std::fabs(gp.depth - depth) <= float(f.rs.depth_threshold) * depth;
        }
        if (!ok) {
            ++c.reuseRejected;
            return;
        }
        ++c.reuseAccepted;
        rec.read(R + gpu_layout::kParticleRecord);  // the previous reservoir and its light
        const ShadingPoint sp = shadingPoint(g, particles);
        Offer offers[2];
        offers[0] = {cur[px], {sp, &f.L, f.rs.candidate_visibility, &f.in.bvh}};
        StoredReservoir prev = h.reservoirs[q];
        const double cap = f.rs.m_cap * double(std::max<std::uint32_t>(cur[px].M, 1));
        prev.M = static_cast<std::uint32_t>(std::min(double(prev.M), std::floor(cap)));
        // The previous frame's visibility needs the previous frame's BVH
        // (kept by the frame renderer when basic_visibility asks for it).
        offers[1] = {prev, {shadingPoint(h.gbuffer.texels[q], h.particles), &h.lights,
                            f.rs.candidate_visibility || f.rs.visibility_reuse,
                            f.in.previousBvh ? f.in.previousBvh : &f.in.bvh}};
        Rng rng(px, f.in.frame, RngPass::restirTemporal, f.in.settings.render.seed);
        out[px] = f.codec.roundTrip(f.sanitize(combine<SM, P, Count>(offers, 2, f.L, f.rs, f.vis, f.shadows, rng, c, rec), px, c));
    });
}

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters spatialResampling(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                   std::vector<StoredReservoir>& out) {
    const std::uint32_t W = f.lg.width, H = f.lg.height;
    const float radius = std::max(1.0f, float(f.rs.spatial_radius) * f.scale);
    const std::uint32_t k = f.rs.spatial_neighbours;
    PassCounters* pc = passCounters<Count>(f, pass::spatialResampling);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(W, H, [&](std::size_t px, std::uint32_t x, std::uint32_t y, LightingCounters& c) {
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        out[px] = cur[px];
        if (!g.hit()) return;
        rec.trip(k);
        rec.read(R + gpu_layout::kParticleRecord);
        rec.write(R);
        Rng rng(px ^ (std::uint64_t(iteration) << 40), f.in.frame, RngPass::restirSpatial, f.in.settings.render.seed);
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        Offer offers[1 + 64];
        std::uint32_t n = 0;
        // With temporal reuse as well, a temporal output also holds samples
        // that passed the previous frame's test, not this pixel's: treating it
        // as tested here is then an approximation (measured by `accretion
        // bias`); exact with temporal off.
        const bool tested = f.rs.candidate_visibility;
        offers[n++] = {cur[px], {sp, &f.L, tested, &f.in.bvh}};
        for (std::uint32_t s = 0; s < k; ++s) {
            // Uniform in the disc of the radius (polar, sqrt for area).
            const float r = radius * std::sqrt(rng.uniform());
            const float phi = 6.28318530718f * rng.uniform();
            const long nx = std::lround(float(x) + r * std::cos(phi));
            const long ny = std::lround(float(y) + r * std::sin(phi));
            if (nx < 0 || ny < 0 || nx >= long(W) || ny >= long(H) || (nx == long(x) && ny == long(y))) {
                ++c.reuseRejected;
                continue;
            }
            const std::size_t q = std::size_t(ny) * W + std::size_t(nx);
            const GBufferTexel& gn = f.lg.texels[q];
            rec.read(gpu_layout::kGBufferTexel);
            if (!similar(g, gn, f.rs)) {
                ++c.reuseRejected;
                continue;
            }
            ++c.reuseAccepted;
            rec.read(R + gpu_layout::kParticleRecord);
            offers[n++] = {cur[q], {shadingPoint(gn, f.in.particles), &f.L, tested, &f.in.bvh}};
        }
        out[px] = f.codec.roundTrip(f.sanitize(combine<SM, P, Count>(offers, n, f.L, f.rs, f.vis, f.shadows, rng, c, rec), px, c));
    });
}

/// One shadow ray for the kept sample; Lr = f I G V W. With visibility
/// reuse, an occluded sample's W is zeroed in the stored reservoir.
template <ShadingModel SM, Primitive P, bool Count>
LightingCounters traceShadowRays(const FrameContext& f, std::vector<StoredReservoir>& res, std::vector<Vec3>& Lr) {
    PassCounters* pc = passCounters<Count>(f, pass::traceShadowRays);
    const std::uint32_t R = f.codec.bytes();
    return forEachPixel(f.lg.width, f.lg.height, [&](std::size_t px, std::uint32_t, std::uint32_t, LightingCounters& c) {
        Lr[px] = Vec3(0.0f);
        const GBufferTexel& g = f.lg.texels[px];
        auto rec = recorder<Count>(pc, px);
        recordHit(rec, f, g);
        rec.write(gpu_layout::kRadiance);
        StoredReservoir& r = res[px];
        if (!g.hit()) return;
        rec.read(R);
        if (!(r.W > 0.0f)) return;
        rec.read(gpu_layout::kParticleRecord);
        if constexpr (Count) rec.hint(f.in.bvh.clusterOf(r.y));
        const ShadingPoint sp = shadingPoint(g, f.in.particles);
        LightTerm t;
        ++c.lightTerms;
        if (!f.L.term<SM>(sp, r.y, t)) return;
        bool seen = true;
        if (f.shadows) {
            ++c.shadowRays;
            rec.trip();
            RayCounters rc;
            seen = visible<P>(f.in.bvh, f.vis, sp, r.y, f.L.packed[r.y].position, f.L.packed[r.y].radius, t, rec.rayCounters(rc));
            rec.ray(rc);
        }
        if (!seen) {
            ++c.shadowOccluded;
            if (f.rs.visibility_reuse) {
                r = f.codec.roundTrip(StoredReservoir{kNoLight, 0.0f, r.M, 0.0f});
                rec.write(R);
            }
            return;
        }
        const Vec3 value = t.value * r.W;
        if (std::isfinite(value.x) && std::isfinite(value.y) && std::isfinite(value.z)) Lr[px] = value;
        else {  // overflow in f I G W: a zero sample (discard: and no reservoir for reuse)
            if (f.reject(px, c)) r = f.codec.roundTrip(StoredReservoir{});
        }
    });
}

/// Bilateral upsample of Lr / rho from the lighting grid: bilinear weights
/// times depth and normal similarity, then times the pixel's own albedo.
void upsampleLighting(const GBuffer& full, const GBuffer& lg, const Particles& particles, const std::vector<Vec3>& lowLr,
                      float scale, const RestirSettings& rs, std::vector<Vec3>& Lr) {
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, full.height), [&](const auto& rows) {
        for (std::uint32_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::uint32_t x = 0; x < full.width; ++x) {
                const std::size_t px = std::size_t(y) * full.width + x;
                const GBufferTexel& g = full.texels[px];
                Lr[px] = Vec3(0.0f);
                if (!g.hit()) continue;
                const float fx = (float(x) + 0.5f) * scale - 0.5f, fy = (float(y) + 0.5f) * scale - 0.5f;
                const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
                Vec3 sum(0.0f);
                float wsum = 0.0f;
                for (int dy = 0; dy < 2; ++dy) {
                    for (int dx = 0; dx < 2; ++dx) {
                        const int lx = std::clamp(x0 + dx, 0, int(lg.width) - 1);
                        const int ly = std::clamp(y0 + dy, 0, int(lg.height) - 1);
                        const float bw = (dx ? fx - float(x0) : 1.0f - (fx - float(x0))) *
                                         (dy ? fy - float(y0) : 1.0f - (fy - float(y0)));
                        const std::size_t q = std::size_t(ly) * lg.width + std::size_t(lx);
                        const GBufferTexel& gl = lg.texels[q];
                        if (!gl.hit() || !similar(g, gl, rs)) continue;
                        const Vec3 rho = particles.albedo[gl.particle];
                        const Vec3 e = glm::max(rho, Vec3(1e-8f));
                        const float w = std::max(bw, 1e-4f);
                        sum += w * lowLr[q] / e;
                        wsum += w;
                    }
                }
                if (wsum > 0.0f) Lr[px] = sum / wsum * particles.albedo[g.particle];
            }
        }
    });
}

template <ShadingModel SM, Primitive P, bool Count>
LightingCounters runFrame(const FrameContext& f, std::vector<StoredReservoir>& a, std::vector<StoredReservoir>& b,
                          std::vector<Vec3>& lowLr, PassTimer& timer, PassRejections& rejected) {
    LightingCounters total;
    auto add = [&](std::string_view name, const LightingCounters& c) {
        total += c;
        if (c.nonFinite) rejected[std::string(name)] += c.nonFinite;
    };
    {
        auto t = timer.scope(pass::generateCandidates);
        add(pass::generateCandidates, f.in.settings.render.source == LightSource::power
                                          ? generateCandidates<SM, P, true, Count>(f, a)
                                          : generateCandidates<SM, P, false, Count>(f, a));
    }
    if (f.rs.temporal && f.prev) {
        auto t = timer.scope(pass::temporalResampling);
        add(pass::temporalResampling, temporalResampling<SM, P, Count>(f, a, b));
        std::swap(a, b);
    }
    if (f.rs.spatial_neighbours > 0) {
        auto t = timer.scope(pass::spatialResampling);
        for (std::uint32_t it = 0; it < f.rs.spatial_iterations; ++it) {
            add(pass::spatialResampling, spatialResampling<SM, P, Count>(f, it, a, b));
            std::swap(a, b);
        }
    }
    {
        auto t = timer.scope(pass::traceShadowRays);
        add(pass::traceShadowRays, traceShadowRays<SM, P, Count>(f, a, lowLr));
    }
    return total;
}

template <ShadingModel SM>
LightingCounters dispatchPrimitive(const FrameContext& f, std::vector<StoredReservoir>& a, std::vector<StoredReservoir>& b,
                                   std::vector<Vec3>& lowLr, PassTimer& timer, PassRejections& rej) {
    const bool spheres = f.in.bvh.settings().primitive == Primitive::sphere;
    if (f.counters)
        return spheres ? runFrame<SM, Primitive::sphere, true>(f, a, b, lowLr, timer, rej)
                       : runFrame<SM, Primitive::billboard, true>(f, a, b, lowLr, timer, rej);
    return spheres ? runFrame<SM, Primitive::sphere, false>(f, a, b, lowLr, timer, rej)
                   : runFrame<SM, Primitive::billboard, false>(f, a, b, lowLr, timer, rej);
}

}  // namespace

bool needsPreviousBvh(const Settings& s) {
    return s.render.estimator == EstimatorKind::restir && s.restir.temporal &&
           s.restir.bias_correction == BiasCorrection::basic && s.restir.basic_visibility &&
           (s.restir.visibility_reuse || s.restir.candidate_visibility) &&
           (s.geometry.build == BuildPolicy::rebuild || s.geometry.build == BuildPolicy::fast_trace);
}

Restir::Restir(const Settings& settings, bool keepHistory)
    : rs_(settings.restir), keepHistory_(keepHistory), codec_(settings.restir) {}

LightingCounters Restir::render(const RestirInputs& in, LightingImage& out, ReservoirImage& aov, PassTimer& timer,
                                PassRejections& rejected) {
    const GBuffer& full = in.gbuffer;
    const std::size_t pixels = std::size_t(full.width) * full.height;
    out.Lr.assign(pixels, Vec3(0.0f));
    out.Lr_stderr.assign(pixels, Vec3(0.0f));
    out.spp.assign(pixels, 0.0f);
    codec_.checkCapacity(in.particles.size(), in.settings.scenePath.empty() ? "restir" : in.settings.scenePath);

    // The lighting grid: the image at resolution_scale, each texel the
    // G-buffer texel of the image pixel that contains its centre.
    const float scale = static_cast<float>(rs_.resolution_scale);
    GBuffer reduced;
    const GBuffer* lg = &full;
    if (scale < 1.0f) {
        reduced.width = std::max(1u, std::uint32_t(std::lround(full.width * scale)));
        reduced.height = std::max(1u, std::uint32_t(std::lround(full.height * scale)));
        reduced.texels.resize(std::size_t(reduced.width) * reduced.height);
        for (std::uint32_t y = 0; y < reduced.height; ++y)
            for (std::uint32_t x = 0; x < reduced.width; ++x) {
                const auto fx = std::min(full.width - 1, std::uint32_t((float(x) + 0.5f) / scale));
                const auto fy = std::min(full.height - 1, std::uint32_t((float(y) + 0.5f) / scale));
                reduced.texels[std::size_t(y) * reduced.width + x] = full.at(fx, fy);
            }
        lg = &reduced;
    }
    const std::size_t lpixels = std::size_t(lg->width) * lg->height;
    const LightArrays L(in.particles, in.settings.shading);
    const History* prev = history_ && history_->gbuffer.width == lg->width && history_->gbuffer.height == lg->height
                              ? history_.get() : nullptr;
    std::vector<std::uint32_t> lowRejected(lpixels, 0);
    FrameContext f{in, rs_, codec_, *lg, L, prev, lg == &full ? 1.0f : float(lg->width) / float(full.width),
                   VisibilityOptions::from(in.settings.render), in.settings.shading.visibility, in.counters,
                   lowRejected.data()};

    std::vector<StoredReservoir> a(lpixels), b(lpixels);
    std::vector<Vec3> lowLr(lpixels);
    LightingCounters counters;
    if (!in.particles.empty()) {
        switch (in.settings.shading.model) {
        case ShadingModel::lambert: counters = dispatchPrimitive<ShadingModel::lambert>(f, a, b, lowLr, timer, rejected); break;
        case ShadingModel::sphere: counters = dispatchPrimitive<ShadingModel::sphere>(f, a, b, lowLr, timer, rejected); break;
        case ShadingModel::isotropic: counters = dispatchPrimitive<ShadingModel::isotropic>(f, a, b, lowLr, timer, rejected); break;
        }
    }

    if (lg == &full) {
        out.Lr = lowLr;
    } else {
        auto t = timer.scope(pass::upsampleLighting);
        upsampleLighting(full, *lg, in.particles, lowLr, f.scale, rs_, out.Lr);
        if (in.counters) {
            // Per image pixel: its texel, then four lighting texels (G-buffer + radiance) as loop trips.
            PassCounters& pc = in.counters->add(pass::upsampleLighting, full.width, full.height);
            for (std::size_t px = 0; px < pixels; ++px) {
                const GBufferTexel& g = full.texels[px];
                ThreadCounters& t = pc.threads[px];
                recordTexel(t, g, in.particles, in.bvh, gpu_layout::kGBufferTexel);
                t.bytesWritten = gpu_layout::kRadiance;
                if (!g.hit()) continue;
                t.trips = 4;
                t.bytesRead += 4 * (gpu_layout::kGBufferTexel + gpu_layout::kRadiance);
            }
        }
    }
    aov.W.assign(pixels, 0.0f);
    aov.M.assign(pixels, 0.0f);
    aov.light.assign(pixels, kNoLight);
    aov.p_hat.assign(pixels, 0.0f);
    out.rejected.assign(pixels, 0.0f);
    for (std::uint32_t y = 0; y < full.height; ++y)
        for (std::uint32_t x = 0; x < full.width; ++x) {
            const std::size_t px = std::size_t(y) * full.width + x;
            if (!full.texels[px].hit()) continue;
            out.spp[px] = 1.0f;
            const auto lx = std::min(lg->width - 1, std::uint32_t(float(x) * f.scale));
            const auto ly = std::min(lg->height - 1, std::uint32_t(float(y) * f.scale));
            const StoredReservoir& r = a[std::size_t(ly) * lg->width + lx];
            out.rejected[px] = float(lowRejected[std::size_t(ly) * lg->width + lx]);
            aov.W[px] = r.W;
            aov.M[px] = float(r.M);
            aov.light[px] = r.W > 0.0f ? r.y : kNoLight;
            aov.p_hat[px] = r.p_hat;
        }

    // History for the next frame.
    if (!keepHistory_) return counters;
    auto h = std::make_shared<History>();
    h->gbuffer = *lg;
    h->particles = in.particles;
    h->lights = LightArrays(h->particles, in.settings.shading);
    h->camera = in.camera;
    h->reservoirs = std::move(a);
    history_ = std::move(h);
    return counters;
}

}  // namespace accretion
