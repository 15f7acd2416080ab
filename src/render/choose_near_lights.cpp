// split's pilot (chooseNearLights): V(k) x (k + rho S) measured on a few
// pixels of a 64-pixel-wide view, to pick the near lights k of a frame
// (docs/MODEL.md section 4).
#include <algorithm>
#include <bit>
#include <limits>
#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "accretion/core/error.h"
#include "accretion/render/estimators.h"
#include "light_loops.h"

namespace accretion {

using namespace light_loops;

std::uint32_t nearLightCount(const RenderSettings& render, std::uint32_t chosen) {
    if (render.near_lights > 0) return render.near_lights;
    ACC_CHECK(chosen > 0);  // automatic k: the frame's pilot (FrameRenderer::chooseFrameNearLights) ran
    return chosen;
}

std::uint32_t farCutSize(const RenderSettings& render) {
    const std::uint32_t twice = render.samples >= NearField::kMaxCut / 2 ? NearField::kMaxCut : 2 * render.samples;
    return std::clamp<std::uint32_t>(std::bit_ceil(twice), kMinFarCut, NearField::kMaxCut);
}

namespace {

/// 64 far samples a pixel: with 16, V(k) came out noisy and low where the
/// far field's rare bright draws dominate (disk_100k at 1080p, frames 0-2:
/// V(1024) 0.32-0.36 and V(16) 1.6-2.6 against 0.55 and 1.34 measured by
/// renders, so k jumped between 32 and 1024 from frame to frame); with 64,
/// 0.46-0.54 and 1.6-1.7 for 0.2 s a frame instead of 0.15.
constexpr std::uint32_t kPilotPixels = 256, kPilotSamples = 64;
/// The pilot's far cut: one size whatever S, so that V(k) does not depend on
/// S: the smallest a render uses (farCutSize); a larger one has about the
/// same variance (disk_100k at 1080p, k = 1024: within 5% from 256 to 1024 nodes).
constexpr std::uint32_t kPilotCutNodes = kMinFarCut;
constexpr double kPilotEpsilon = 1e-2;  ///< relMSE's (analysis/image_metrics.h: kRelMseEpsilon)

/// One pilot pixel at every candidate k: per-channel far-sample variance,
/// and the estimate (near sum + far mean) at the largest k. The near fields
/// are nearestToParticle's: one search for the largest k, whose first k
/// lights are the search's for each smaller k.
template <ShadingModel M, Primitive P>
void pilotPixel(const LightingInputs& in, const LightArrays& L, const VisibilityOptions& vis, std::size_t px,
                const std::vector<std::uint32_t>& ks, NearField& field, double* variance, DVec3& value) {
    const GBufferTexel& g = in.gbuffer.texels[px];
    const ShadingPoint sp = shadingPoint(g, in.particles);
    const bool shadows = in.shading.visibility;
    static_assert(kPilotSamples % LightingPlan::kChunkSamples == 0);
    const ShadingPoint centre = particleCentre(in, g.particle, sp.n);
    std::uint32_t nearest[NearField::kMaxLights];
    const std::uint32_t found = in.lightTree->nearestLights(centre, ks.back(), nearest);
    for (std::size_t c = 0; c < ks.size(); ++c) {
        std::uint32_t lights[NearField::kMaxLights];
        const std::uint32_t count = std::min(ks[c], found);
        std::copy(nearest, nearest + count, lights);
        lights[count] = g.particle;  // as nearest() adds it
        in.lightTree->nearField(centre, lights, count + 1, field, kPilotCutNodes);
        PixelSums far;  // the far samples alone, drawn and shaded as the render's are
        far.discardNonFinite = in.render.nonfinite == NonFinitePolicy::discard;
        // The same stream at every k: the candidates differ by their near field alone.
        Rng rng(px, in.frame, RngPass::nearLightPilot, in.render.seed);
        LightSample xs[LightingPlan::kChunkSamples];
        for (std::uint32_t s = 0; s < kPilotSamples; s += LightingPlan::kChunkSamples) {
            drawLights<EstimatorKind::split>(in, L, sp, &field, rng, LightingPlan::kChunkSamples, xs);
            shadeSamples<M, P>(in.bvh, L, sp, xs, LightingPlan::kChunkSamples, DVec3(0.0), vis, shadows, far, nullptr);
        }
        const double n = std::max(far.n, 2u);
        const DVec3 var = glm::max(DVec3(0.0), (far.sumSq - far.sum * far.sum / n) / (n - 1.0));
        for (int ch = 0; ch < 3; ++ch) variance[c * 3 + ch] = var[ch];
        if (c + 1 == ks.size())  // the pixel's value: the largest k's near sum and far mean
            value = sumTerms<M, P>(in.bvh, L, sp, std::span<const std::uint32_t>(field.light, field.count), vis, shadows,
                                   far.c, nullptr) + far.sum / n;
    }
}

template <ShadingModel M, Primitive P>
NearLightChoice choosePilot(const LightingInputs& in, const LightArrays& L) {
    NearLightChoice choice;
    std::vector<std::size_t> lit;
    for (std::size_t px = 0; px < in.gbuffer.texels.size(); ++px)
        if (in.gbuffer.texels[px].hit()) lit.push_back(px);
    std::vector<std::size_t> pixels;
    for (std::size_t i = 0; i < std::min<std::size_t>(lit.size(), kPilotPixels); ++i)
        pixels.push_back(lit[i * lit.size() / std::min<std::size_t>(lit.size(), kPilotPixels)]);
    std::vector<std::uint32_t> ks;
    const std::uint32_t most = in.particles.size() > 1 ? std::uint32_t(in.particles.size() - 1) : 0u;
    for (std::uint32_t k = 16; k <= NearField::kMaxNear; k *= 2) {
        ks.push_back(std::min(k, most));
        if (k >= most) break;
    }
    choice.pixels = static_cast<std::uint32_t>(pixels.size());
    if (pixels.empty() || most == 0) {
        choice.k = 16;
        return choice;
    }
    std::vector<double> variance(pixels.size() * ks.size() * 3);
    std::vector<DVec3> value(pixels.size());
    const VisibilityOptions vis = VisibilityOptions::from(in.render);
    tbb::enumerable_thread_specific<std::unique_ptr<NearField>> fields;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels.size(), 4), [&](const auto& r) {
        std::unique_ptr<NearField>& field = fields.local();
        if (!field) field = std::make_unique<NearField>();
        for (std::size_t i = r.begin(); i != r.end(); ++i)
            pilotPixel<M, P>(in, L, vis, pixels[i], ks, *field, &variance[i * ks.size() * 3], value[i]);
    });
    // V(k), summed in pixel order (the same whatever the threads).
    const double samples = double(in.render.samples) * NearLightChoice::kFarSampleCost;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < ks.size(); ++c) {
        double v = 0.0;
        for (std::size_t i = 0; i < pixels.size(); ++i)
            for (int ch = 0; ch < 3; ++ch)
                v += variance[(i * ks.size() + c) * 3 + ch] / (value[i][ch] * value[i][ch] + kPilotEpsilon);
        v /= 3.0 * double(pixels.size());
        const double cost = double(ks[c]) + samples;
        choice.candidates.push_back({ks[c], v, cost});
        // Ties (every far sample zero, or no far light left) go to the smaller k.
        if (v * cost < best) {
            best = v * cost;
            choice.k = ks[c];
        }
    }
    return choice;
}

}  // namespace

NearLightChoice chooseNearLights(const LightingInputs& pilot) {
    ACC_CHECK(pilot.lightTree);
    const LightArrays L(pilot.particles, pilot.shading);
    const bool spheres = pilot.bvh.settings().primitive == Primitive::sphere;
    switch (pilot.shading.model) {
    case ShadingModel::lambert:
        return spheres ? choosePilot<ShadingModel::lambert, Primitive::sphere>(pilot, L)
                       : choosePilot<ShadingModel::lambert, Primitive::billboard>(pilot, L);
    case ShadingModel::sphere:
        return spheres ? choosePilot<ShadingModel::sphere, Primitive::sphere>(pilot, L)
                       : choosePilot<ShadingModel::sphere, Primitive::billboard>(pilot, L);
    case ShadingModel::isotropic:
        return spheres ? choosePilot<ShadingModel::isotropic, Primitive::sphere>(pilot, L)
                       : choosePilot<ShadingModel::isotropic, Primitive::billboard>(pilot, L);
    }
    return {};
}


}  // namespace accretion
