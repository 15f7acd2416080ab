#include "accretion/render/estimators.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "accretion/core/error.h"
#include "accretion/core/rng.h"
#include "accretion/gpu/gpu_layouts.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/render/shading.h"
#include "accretion/render/visibility.h"

namespace accretion {
namespace {

ShadingPoint shadingPoint(const GBufferTexel& g, const Particles& particles) {
    return {g.position, g.normal, g.geomNormal, particles.albedo[g.particle], g.particle};
}

/// exact: sum over every light i != j of f I G V, in double.
template <ShadingModel M, Primitive P>
Vec3 exactPixel(const ParticleBvh& bvh, const LightArrays& L, const ShadingPoint& sp, float eps, bool shadows,
                LightingCounters& c, RayCounters* rc) {
    DVec3 sum(0.0);
    for (std::uint32_t i = 0; i < L.count; ++i) {
        if (i == sp.self) continue;
        LightTerm t;
        ++c.lightTerms;
        if (!evalLight<M>(sp, L.position[i], L.emission[i], L.packed[i].dmin2, t)) continue;
        if (!shadows) {
            sum += DVec3(t.value);
            continue;
        }
        ++c.shadowRays;
        if (visible<P>(bvh, sp, t, L.packed[i].radius, eps, rc)) sum += DVec3(t.value);
        else ++c.shadowOccluded;
    }
    return Vec3(sum);
}

/// Mean and standard error of the mean of S per-sample estimates (0 counts).
class SampleMean {
public:
    void add(const DVec3& x) {
        s1_ += x;
        s2_ += x * x;
    }
    void finish(std::uint32_t S, Vec3& mean, Vec3& stderr) const {
        const DVec3 m = s1_ / double(S);
        mean = Vec3(m);
        const DVec3 var = S > 1 ? glm::max((s2_ - double(S) * m * m) / double(S - 1), DVec3(0.0)) : DVec3(0.0);
        stderr = Vec3(glm::sqrt(var / double(S)));
    }

private:
    DVec3 s1_{0.0}, s2_{0.0};
};

/// uniform / power / tree: one-sample estimates f I G V / p(i) (0 when no
/// light or i = j), in rounds of S until the relative standard error of the
/// luminance reaches the target (or max_samples); one round when the target is 0.
template <ShadingModel M, Primitive P, class Sampler>
std::uint32_t sampledPixel(const ParticleBvh& bvh, const LightArrays& L, Sampler&& sampleOne, const ShadingPoint& sp,
                           const RenderSettings& rs, float eps, bool shadows, Rng& rng, Vec3& mean, Vec3& stderr,
                           LightingCounters& c, RayCounters* rc) {
    SampleMean acc;
    std::uint32_t n = 0;
    for (;;) {
        // Lights drawn 8 at a time and prefetched: their records are random
        // accesses (a cache miss each); the RNG is consumed in the same order.
        for (std::uint32_t k0 = 0; k0 < rs.samples; k0 += 8) {
            const std::uint32_t batch = std::min<std::uint32_t>(8, rs.samples - k0);
            LightSample xs[8];
            for (std::uint32_t k = 0; k < batch; ++k) {
                xs[k] = sampleOne(rng);
                if (xs[k].i < L.count) __builtin_prefetch(&L.packed[xs[k].i]);
            }
            for (std::uint32_t k = 0; k < batch; ++k) {
                const LightSample& x = xs[k];
                LightTerm t;
                ++c.lightTerms;
                if (!L.term<M>(sp, x.i, t)) continue;
                if (shadows) {
                    ++c.shadowRays;
                    if (!visible<P>(bvh, sp, t, L.packed[x.i].radius, eps, rc)) {
                        ++c.shadowOccluded;
                        continue;
                    }
                }
                acc.add(DVec3(t.value) / double(x.pdf));
            }
        }
        n += rs.samples;
        acc.finish(n, mean, stderr);
        if (!(rs.target_stderr > 0.0) || n + rs.samples > rs.max_samples) return n;
        if (luminance(stderr) <= rs.target_stderr * luminance(mean)) return n;
    }
}

/// ris (MODEL.md section 4): per sample, one reservoir streams M candidates
/// from the source pmf with w = p_hat / p_src, p_hat = luminance(f I G)
/// without visibility; the kept y gets one shadow ray, weighted by W.
template <ShadingModel M, Primitive P, bool Power>
void risPixel(const ParticleBvh& bvh, const LightArrays& L, const AliasTable* table, const ShadingPoint& sp,
              const RenderSettings& rs, float eps, bool shadows, Rng& rng, Vec3& mean, Vec3& stderr,
              LightingCounters& c, RayCounters* rc) {
    SampleMean acc;
    for (std::uint32_t k = 0; k < rs.samples; ++k) {
        Reservoir r;
        LightTerm t_y{};
        for (std::uint32_t m = 0; m < rs.candidates; ++m) {
            const LightSample x = sampleSource<Power>(L, table, rng);
            LightTerm t;
            float p_hat = 0.0f;
            ++c.lightTerms;
            if (L.term<M>(sp, x.i, t)) p_hat = luminance(t.value);
            if (r.update(x.i, p_hat / x.pdf, p_hat, rng.uniform())) t_y = t;
        }
        r.finalize();
        if (r.W <= 0.0f) continue;
        if (shadows) {
            ++c.shadowRays;
            if (!visible<P>(bvh, sp, t_y, L.packed[r.y].radius, eps, rc)) {
                ++c.shadowOccluded;
                continue;
            }
        }
        acc.add(DVec3(t_y.value) * double(r.W));
    }
    acc.finish(rs.samples, mean, stderr);
}

/// Counters (counting mode): per pixel, its key, the light terms as loop
/// trips, the shadow rays with their traversal counts, and bytes.
template <ShadingModel M, Primitive P, bool Count>
LightingCounters run(const LightingInputs& in, const LightArrays& L, LightingImage& out, Progress* progress) {
    const GBuffer& gb = in.gbuffer;
    const float eps = static_cast<float>(in.render.shadow_epsilon);
    const EstimatorKind kind = in.render.estimator;
    const bool shadows = in.shading.visibility;  // off: V = 1, no shadow rays
    const std::uint32_t S = in.render.samples;
    tbb::enumerable_thread_specific<LightingCounters> counters;

    tbb::parallel_for(tbb::blocked_range2d<std::uint32_t>(0, gb.height, 8, 0, gb.width, 8), [&](const auto& r) {
        LightingCounters& c = counters.local();
        for (std::uint32_t y = r.rows().begin(); y != r.rows().end(); ++y) {
            for (std::uint32_t x = r.cols().begin(); x != r.cols().end(); ++x) {
                const std::size_t px = std::size_t(y) * gb.width + x;
                const GBufferTexel& g = gb.texels[px];
                [[maybe_unused]] const LightingCounters before = c;
                RayCounters raySum;
                RayCounters* rc = Count ? &raySum : nullptr;
                const auto record = [&] {
                    if constexpr (Count) {
                        ThreadCounters& t = in.counters->threads[px];
                        recordTexel(t, g, in.particles, in.bvh, gpu_layout::kGBufferTexel);
                        t.bytesWritten += gpu_layout::kRadiance;
                        if (!g.hit()) return;
                        t.trips = static_cast<std::uint32_t>(c.lightTerms - before.lightTerms);
                        t.bytesRead += t.trips * gpu_layout::kParticleRecord;
                        t.addRays(raySum, static_cast<std::uint32_t>(c.shadowRays - before.shadowRays));
                    }
                };
                if (!g.hit()) {
                    record();
                    continue;
                }
                const ShadingPoint sp = shadingPoint(g, in.particles);
                if (kind == EstimatorKind::exact) {
                    out.Lr[px] = exactPixel<M, P>(in.bvh, L, sp, eps, shadows, c, rc);
                    record();
                    continue;
                }
                Rng rng(px, in.frame, RngPass::lightSampling, in.render.seed);
                Vec3& mean = out.Lr[px];
                Vec3& err = out.Lr_stderr[px];
                std::uint32_t n = S;
                if (kind == EstimatorKind::ris && in.render.source == LightSource::power)
                    risPixel<M, P, true>(in.bvh, L, in.powerTable, sp, in.render, eps, shadows, rng, mean, err, c, rc);
                else if (kind == EstimatorKind::ris)
                    risPixel<M, P, false>(in.bvh, L, nullptr, sp, in.render, eps, shadows, rng, mean, err, c, rc);
                else if (kind == EstimatorKind::power)
                    n = sampledPixel<M, P>(in.bvh, L, [&](Rng& g) { return sampleSource<true>(L, in.powerTable, g); },
                                           sp, in.render, eps, shadows, rng, mean, err, c, rc);
                else if (kind == EstimatorKind::tree)
                    n = sampledPixel<M, P>(in.bvh, L, [&](Rng& g) { return in.lightTree->sample(sp, g); }, sp,
                                           in.render, eps, shadows, rng, mean, err, c, rc);
                else
                    n = sampledPixel<M, P>(in.bvh, L, [&](Rng& g) { return sampleSource<false>(L, nullptr, g); }, sp,
                                           in.render, eps, shadows, rng, mean, err, c, rc);
                out.spp[px] = float(n);
                record();
            }
        }
        if (progress) progress->advance(std::uint64_t(r.rows().size()) * r.cols().size());
    });
    LightingCounters total;
    for (const auto& c : counters) total += c;
    return total;
}

template <ShadingModel M>
LightingCounters dispatchPrimitive(const LightingInputs& in, const LightArrays& L, LightingImage& out, Progress* p) {
    const bool spheres = in.bvh.settings().primitive == Primitive::sphere;
    if (in.counters)
        return spheres ? run<M, Primitive::sphere, true>(in, L, out, p) : run<M, Primitive::billboard, true>(in, L, out, p);
    return spheres ? run<M, Primitive::sphere, false>(in, L, out, p) : run<M, Primitive::billboard, false>(in, L, out, p);
}

}  // namespace

bool needsPowerTable(const RenderSettings& r) {
    const bool resampling = r.estimator == EstimatorKind::ris || r.estimator == EstimatorKind::restir;
    return r.estimator == EstimatorKind::power || (resampling && r.source == LightSource::power);
}

AliasTable buildPowerTable(const Particles& particles) {
    std::vector<float> w(particles.size());
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = luminance(particles.emission[i]);
    return AliasTable(w);
}

LightingCounters estimateLighting(const LightingInputs& in, LightingImage& out, Progress* progress) {
    const std::size_t pixels = std::size_t(in.gbuffer.width) * in.gbuffer.height;
    out.Lr.assign(pixels, Vec3(0.0f));
    out.Lr_stderr.assign(pixels, Vec3(0.0f));
    out.spp.assign(pixels, 0.0f);
    if (in.particles.empty()) return {};
    ACC_CHECK(!needsPowerTable(in.render) || in.powerTable);

    ACC_CHECK(in.render.estimator != EstimatorKind::tree || in.lightTree);
    ACC_CHECK(in.render.estimator != EstimatorKind::restir);
    const LightArrays L(in.particles, in.shading);
    switch (in.shading.model) {
    case ShadingModel::lambert: return dispatchPrimitive<ShadingModel::lambert>(in, L, out, progress);
    case ShadingModel::sphere: return dispatchPrimitive<ShadingModel::sphere>(in, L, out, progress);
    case ShadingModel::isotropic: return dispatchPrimitive<ShadingModel::isotropic>(in, L, out, progress);
    }
    return {};
}

}  // namespace accretion
