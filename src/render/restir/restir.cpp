// Restir: one frame of ReSTIR DI, the passes in the order the plan gives.
#include "accretion/render/restir.h"

#include "accretion/core/error.h"
#include "accretion/render/particle_texel_grid.h"
#include "accretion/render/upsample_pixel.h"
#include "restir_pass.h"

namespace accretion {
namespace {

/// The plan's restir passes: presampleLightTiles and presampleRegirGrid
/// (sources tiles, regir), generateCandidates, temporalResampling,
/// spatialResampling (plan.spatialIterations times), traceShadowRays.
/// With a trace (render --pixel), the reservoir of texel `traced` after each pass.
LightingCounters runPasses(restir::FrameContext& f, std::vector<StoredReservoir>& a, std::vector<StoredReservoir>& b,
                           std::vector<Vec3>& lowLr, PassTimer& timer, PassRejections& rejected, PassReuse& reuse,
                           std::size_t traced) {
    const FramePlan& plan = f.in.plan;
    LightingCounters total;
    auto add = [&](Pass pass, const LightingCounters& c) {
        total += c;
        if (c.nonFinite) rejected[pass] += c.nonFinite;
        if (c.reuse.offered()) reuse[pass] += c.reuse;
    };
    auto snapshot = [&](PassRun run, const std::vector<StoredReservoir>& r) {
        if (f.in.trace) f.in.trace->passes.push_back({run, r[traced]});
    };
    LightTiles tiles;
    RegirGrid grid;
    if (plan.presampleTiles) {
        auto t = timer.scope(Pass::presampleLightTiles);
        tiles = restir::presampleLightTiles(f);
        f.tiles = &tiles;
    }
    if (plan.presampleRegir) {
        auto t = timer.scope(Pass::presampleRegirGrid);
        grid = restir::presampleRegirGrid(f);
        f.regir = &grid;
    }
    {
        auto t = timer.scope(Pass::generateCandidates);
        add(Pass::generateCandidates, restir::generateCandidates(f, a));
    }
    snapshot({Pass::generateCandidates}, a);
    const bool particles = plan.particleTexels;  // history by id, world neighbours
    if (plan.temporal) {
        auto t = timer.scope(Pass::temporalResampling);
        add(Pass::temporalResampling, particles ? restir::temporalResamplingById(f, a, b) : restir::temporalResampling(f, a, b));
        std::swap(a, b);
        snapshot({Pass::temporalResampling}, a);
    }
    if (plan.spatialIterations > 0) {  // particle_restir's neighbours in world order, restir's in a screen disc
        const Pass spatial = particles ? Pass::resampleWorldNeighbours : Pass::spatialResampling;
        auto t = timer.scope(spatial);
        for (std::uint32_t it = 0; it < plan.spatialIterations; ++it) {
            add(spatial, particles ? restir::resampleWorldNeighbours(f, it, a, b) : restir::spatialResampling(f, it, a, b));
            std::swap(a, b);
            snapshot({spatial, it + 1}, a);
        }
    }
    if (plan.traceShadowRays) {
        auto t = timer.scope(Pass::traceShadowRays);
        add(Pass::traceShadowRays, restir::traceShadowRays(f, a, lowLr));
        if (plan.texelHistory) restir::accumulateTexelLr(f, lowLr);
    }
    return total;
}

/// A frame that is a window of the image (restir.crop_margin): its grid's
/// texels keyed by their place in the whole grid (ReuseParams::pixelKey),
/// the window's origin at `scale` x its pixel origin.
void keyByWholeGrid(restir::FrameContext& f, const Camera& camera, float scale, std::uint32_t wholeWidth) {
    f.originX = std::uint32_t(camera.pixelX0 * scale);
    f.originY = std::uint32_t(camera.pixelY0 * scale);
    f.wholeWidth = wholeWidth;
}

/// particle_restir's reservoir AOVs: each hit pixel's spp, the reservoir of
/// its particle's first texel, and the non-finite values rejected at the
/// pixel and at its particle's texels (those its Lr was made from).
void writeTexelAovs(const GBuffer& full, const ParticleTexels& texels, const std::vector<StoredReservoir>& a,
                    const std::vector<std::uint32_t>& pixelRejected, const std::vector<std::uint32_t>& texelRejected,
                    LightingImage& out, ReservoirImage& aov) {
    const std::size_t pixels = full.texels.size();
    aov.W.assign(pixels, 0.0f);
    aov.M.assign(pixels, 0.0f);
    aov.light.assign(pixels, kNoLight);
    aov.p_hat.assign(pixels, 0.0f);
    out.rejected.assign(pixels, 0.0f);
    for (std::size_t px = 0; px < pixels; ++px) {
        const GBufferTexel& g = full.texels[px];
        if (!g.hit()) continue;
        out.spp[px] = 1.0f;
        const std::size_t first = std::size_t(texels.slotOf[g.particle]) * texels.perParticle();
        std::uint32_t rejected = pixelRejected[px];
        for (std::size_t k = 0; k < texels.perParticle(); ++k) rejected += texelRejected[first + k];
        out.rejected[px] = float(rejected);
        const StoredReservoir& r = a[first];
        aov.W[px] = r.W;
        aov.M[px] = float(r.M);
        aov.light[px] = r.W > 0.0f ? r.y : kNoLight;
        aov.p_hat[px] = r.p_hat;
    }
}

/// The lighting grid at resolution_scale: each texel the G-buffer texel of
/// the image pixel that contains its centre.
GBuffer reduceToLightingGrid(const GBuffer& full, float scale) {
    GBuffer reduced;
    reduced.width = lightingGridExtent(full.width, scale);
    reduced.height = lightingGridExtent(full.height, scale);
    reduced.window = PixelWindow::whole(reduced.width, reduced.height);
    reduced.texels.resize(std::size_t(reduced.width) * reduced.height);
    for (std::uint32_t y = 0; y < reduced.height; ++y)
        for (std::uint32_t x = 0; x < reduced.width; ++x) {
            std::uint32_t fx, fy;
            reducedTexelSource(x, y, scale, full.width, full.height, fx, fy);
            reduced.texels[std::size_t(y) * reduced.width + x] = full.at(fx, fy);
        }
    return reduced;
}

/// Each hit pixel's spp, rejections and reservoir AOVs, from its lighting
/// texel's final reservoir (texelOf: image pixel -> lighting texel).
template <class TexelOf>
void writeReservoirAovs(const GBuffer& full, const std::vector<StoredReservoir>& a, const std::vector<std::uint32_t>& lowRejected,
                        const TexelOf& texelOf, LightingImage& out, ReservoirImage& aov) {
    const std::size_t pixels = std::size_t(full.width) * full.height;
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
            const std::size_t lpx = texelOf(x, y);
            const StoredReservoir& r = a[lpx];
            out.rejected[px] = float(lowRejected[lpx]);
            aov.W[px] = r.W;
            aov.M[px] = float(r.M);
            aov.light[px] = r.W > 0.0f ? r.y : kNoLight;
            aov.p_hat[px] = r.p_hat;
        }
}

}  // namespace

Restir::Restir(const Settings& settings, bool keepHistory)
    : rs_(settings.restir), keepHistory_(keepHistory), codec_(settings.restir) {}

LightingCounters Restir::render(const RestirInputs& in, LightingImage& out, ReservoirImage& aov, PassTimer& timer,
                                PassRejections& rejected, PassReuse& reuse) {
    const GBuffer& full = in.gbuffer;
    ACC_CHECK(full.whole());  // spatial reuse reads the neighbours, history is the frame's (or its window's: restir.crop_margin)
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
    if (in.plan.upsample) {
        reduced = reduceToLightingGrid(full, scale);
        lg = &reduced;
    }
    ParticleTexels texels;  // particle_restir: the lighting grid is the visible particles' texels
    if (in.plan.particleTexels) {
        auto t = timer.scope(Pass::gatherParticleTexels);
        texels = gatherParticleTexels(full, in.particles, in.bvh, in.camera, in.settings.shading.model, rs_.texels, rs_.texel_rays,
                                      TexelPointRule{});
        if (in.counters)
            recordGatherParticleTexels(full, in.particles, in.bvh, texels, in.counters->add(Pass::gatherParticleTexels, full.width, full.height));
        lg = &texels.grid;
    }
    const std::size_t lpixels = std::size_t(lg->width) * lg->height;
    const LightArrays L(in.particles, in.settings.shading);
    const FramePlan& plan = in.plan;
    ACC_CHECK(plan.restir);
    ACC_CHECK((plan.sampler == LightSamplerKind::power) == (in.powerTable != nullptr));  // candidates from the planned source
    ACC_CHECK((plan.sampler == LightSamplerKind::tree) == (in.lightTree != nullptr));
    ACC_CHECK(!plan.temporal || (history_ && (plan.particleTexels || (history_->gbuffer.width == lg->width &&
                                                                        history_->gbuffer.height == lg->height))));
    const History* prev = plan.temporal ? history_.get() : nullptr;
    std::vector<std::uint32_t> lowRejected(lpixels, 0);
    restir::FrameContext f{in, rs_, codec_, *lg, L, prev, lg == &reduced ? float(lg->width) / float(full.width) : 1.0f,
                   VisibilityOptions::from(in.settings.render), plan.shadowRays, in.counters,
                   lowRejected.data()};
    if (plan.particleTexels) f.texels = &texels;

    if (in.camera.isWindow() && !plan.particleTexels)  // restir.crop_margin: the frame's window
        keyByWholeGrid(f, in.camera, f.scale, lg == &full ? in.camera.imageWidth : lightingGridExtent(in.camera.imageWidth, scale));
    // particle_restir's texels are keyed by particle: their reuse is counted whatever render.crop.
    if (!in.settings.render.crop.empty() && !plan.particleTexels) {  // reuse is counted over render.crop's texels, not the rest rendered for it
        const PixelWindow crop = PixelWindow::of(in.settings);
        const auto at = [&](std::uint32_t v, float o) { return std::uint32_t(std::max(0.0f, (float(v) - o) * f.scale)); };
        f.counted = {at(crop.x0, in.camera.pixelX0), at(crop.x1, in.camera.pixelX0), at(crop.y0, in.camera.pixelY0),
                     at(crop.y1, in.camera.pixelY0)};
    }
    std::vector<StoredReservoir> a(lpixels), b(lpixels);
    std::vector<Vec3> lowLr(lpixels);
    // The lighting texel of image pixel (x, y).
    const auto texelOf = [&](std::uint32_t x, std::uint32_t y) {
        return std::size_t(std::min(lg->height - 1, std::uint32_t(float(y) * f.scale))) * lg->width +
               std::min(lg->width - 1, std::uint32_t(float(x) * f.scale));
    };
    std::size_t traced = 0;
    if (in.trace) {  // its pixel of the image, in this frame's window
        const auto x = std::uint32_t(in.trace->px % in.camera.imageWidth) - std::uint32_t(in.camera.pixelX0);
        const auto y = std::uint32_t(in.trace->px / in.camera.imageWidth) - std::uint32_t(in.camera.pixelY0);
        ACC_CHECK(x < full.width && y < full.height);
        const GBufferTexel& g = full.at(x + full.window.x0, y + full.window.y0);
        traced = !plan.particleTexels ? texelOf(x, y) : g.hit() ? std::size_t(texels.slotOf[g.particle]) * texels.perParticle() : 0;
    }
    LightingCounters counters = runPasses(f, a, b, lowLr, timer, rejected, reuse, traced);

    if (plan.particleTexels) {  // the pixels from their particles' texels, each as restir keys a pixel
        const Pass pass = plan.resamplePixels ? Pass::resampleParticlePixels : Pass::shadeParticlePixels;
        auto t = timer.scope(pass);
        RestirSettings pixelRs = rs_;  // no canonical sample at the pixel: pairwise MIS has nothing to weigh against
        if (pixelRs.bias_correction == BiasCorrection::pairwise) pixelRs.bias_correction = BiasCorrection::basic;
        std::vector<std::uint32_t> pixelRejected(pixels, 0);
        restir::FrameContext fp{in, pixelRs, codec_, full, L, prev, 1.0f, f.vis, plan.shadowRays, in.counters, pixelRejected.data()};
        fp.texels = &texels;
        if (in.camera.isWindow()) keyByWholeGrid(fp, in.camera, 1.0f, in.camera.imageWidth);
        const LightingCounters c = plan.resamplePixels ? restir::resampleParticlePixels(fp, a, out.Lr) : restir::shadeParticlePixels(fp, lowLr, out.Lr);
        counters += c;
        if (c.nonFinite) rejected[pass] += c.nonFinite;
        writeTexelAovs(full, texels, a, pixelRejected, lowRejected, out, aov);
    } else if (!plan.upsample) {
        out.Lr = lowLr;
    } else {
        auto t = timer.scope(Pass::upsampleLighting);
        restir::upsampleLighting(full, *lg, in.particles, lowLr, f.scale, rs_, out.Lr);
        if (in.counters) restir::recordUpsample(in, *lg, in.counters->add(Pass::upsampleLighting, full.width, full.height));
    }
    if (!plan.particleTexels) writeReservoirAovs(full, a, lowRejected, texelOf, out, aov);

    // History for the next frame.
    if (!keepHistory_) return counters;
    auto h = std::make_shared<History>();
    h->gbuffer = *lg;
    h->slotOf = std::move(texels.slotOf);
    if (plan.particleTexels && rs_.texel_history > 0.0) h->texelLr = lowLr;
    h->particles = in.particles;
    h->lights = LightArrays(h->particles, in.settings.shading);
    h->camera = in.camera;
    h->reservoirs = std::move(a);
    history_ = std::move(h);
    return counters;
}

}  // namespace accretion
