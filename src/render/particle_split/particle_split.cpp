// ParticleSplit: one particle_split frame, its passes in the plan's order.
#include "accretion/render/particle_split.h"

#include "accretion/core/error.h"
#include "accretion/render/particle_texel_grid.h"
#include "cpu_split_bridge.h"

namespace accretion {

LightingCounters ParticleSplit::render(const ParticleSplitInputs& in, LightingImage& out, PassTimer& timer) {
    const FramePlan& plan = in.plan;
    ACC_CHECK(plan.particleSplit && plan.sampler == LightSamplerKind::tree);
    const std::size_t pixels = in.gbuffer.texels.size();
    out.Lr.assign(pixels, Vec3(0.0f));
    out.Lr_stderr.assign(pixels, Vec3(0.0f));
    out.spp.assign(pixels, 0.0f);
    out.rejected.assign(pixels, 0.0f);

    ParticleTexels texels;
    {
        auto t = timer.scope(Pass::gatherParticleTexels);
        texels = gatherParticleTexels(in.gbuffer, in.particles, in.bvh, in.camera, in.settings.shading.model, ps_.texels, 1,
                                      psplit::texelPoints(in.settings, in.frame, in.settings.render.seed));
        if (in.counters)
            recordGatherParticleTexels(in.gbuffer, in.particles, in.bvh, texels,
                                       in.counters->add(Pass::gatherParticleTexels, in.gbuffer.width, in.gbuffer.height));
    }
    const psplit::SplitParams params = psplit::splitParams(in.settings, texels.visible(), in.frame, in.settings.render.seed);
    const LightArrays L(in.particles, in.settings.shading);
    std::vector<std::uint32_t> near(std::size_t(texels.visible()) * params.nearCount), nearFound(texels.visible());
    std::vector<float> nearRadius2(texels.visible());
    std::vector<Vec3> texelLr(texels.grid.texels.size());
    std::vector<Vec3> texelFar(params.history > 0.0f && params.historyOfFar ? texels.grid.texels.size() : 0);
    std::vector<std::uint32_t> texelAge(params.history > 0.0f && params.historyMean ? texels.grid.texels.size() : 0);
    const bool handoff = params.keepsNearTerms();
    std::vector<Vec3> texelNear(handoff ? texels.grid.texels.size() * params.nearCount : 0);
    std::vector<std::uint32_t> texelRejected(texels.grid.texels.size(), 0);
    std::vector<std::uint32_t> newIndex;  // far_new's texels without history (shadeSplitTexels)
    const std::vector<std::uint64_t> paths = in.lightTree.paths();
    // Last frame's texels: kept only with a history, so empty without one.
    const psplit::CpuFrame f{in, params, L, in.lightTree.view(), paths, VisibilityOptions::from(in.settings.render), plan.shadowRays,
                             texels, near, nearFound, nearRadius2, prevSlotOf_, prevNear_, prevNearFound_, prevTexelLr_, texelLr, prevTexelFar_, texelFar, prevTexelAge_, texelAge, prevTexelNear_, texelNear, texelRejected, newIndex, out.Lr};
    LightingCounters counters;
    {
        auto t = timer.scope(Pass::findNearLights);
        counters += psplit::findNearLights(f);
    }
    {
        auto t = timer.scope(Pass::shadeSplitTexels);
        counters += psplit::shadeSplitTexels(f);
    }
    {
        auto t = timer.scope(Pass::shadeParticlePixels);
        counters += psplit::shadeSplitPixels(f);
    }
    // Per hit pixel: one estimate, and the rejections of its particle's texels.
    const std::uint32_t per = params.texelsPerParticle();
    for (std::size_t px = 0; px < pixels; ++px) {
        const GBufferTexel& g = in.gbuffer.texels[px];
        if (!g.hit()) continue;
        out.spp[px] = 1.0f;
        const std::size_t first = std::size_t(texels.slotOf[g.particle]) * per;
        std::uint32_t rejected = 0;
        for (std::uint32_t k = 0; k < per; ++k) rejected += texelRejected[first + k];
        out.rejected[px] = float(rejected);
    }
    if (params.history > 0.0f) {
        prevSlotOf_ = std::move(texels.slotOf);
        prevTexelLr_ = std::move(texelLr);
        prevTexelFar_ = std::move(texelFar);
        prevTexelAge_ = std::move(texelAge);
        if (handoff) {
            prevNear_ = std::move(near);
            prevNearFound_ = std::move(nearFound);
            prevTexelNear_ = std::move(texelNear);
        }
    }
    return counters;
}

}  // namespace accretion
