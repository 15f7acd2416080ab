#include "accretion/render/frame_renderer.h"

#include <chrono>
#include <limits>

#include <fmt/format.h>

namespace accretion {

FrameRenderer::FrameRenderer(const Settings& settings, ParticleSource source, RenderOptions options)
    : settings_(settings), source_(std::move(source)), options_(options),
      device_(std::make_unique<EmbreeDevice>()),
      bvh_(std::make_unique<ParticleBvh>(*device_, settings.geometry, settings.gpu)) {
    if (settings_.render.estimator == EstimatorKind::restir) restir_ = std::make_unique<Restir>(settings_);
}

FrameRenderer::~FrameRenderer() = default;

FrameImage FrameRenderer::render(std::uint32_t frame, FrameStats& stats) {
    const auto start = std::chrono::steady_clock::now();
    stats.frame = frame;
    const Camera camera = Camera::atFrame(settings_.camera, frame);
    PassTimer& timer = stats.timer;

    Particles particles;
    {
        auto t = timer.scope(pass::loadParticles);
        particles = source_.frame(frame);
    }
    stats.particles = particles.size();
    {
        auto t = timer.scope(pass::buildClusters);
        if (needsPreviousBvh(settings_)) {  // double buffer: last frame's BVH stays valid
            std::swap(bvh_, previousBvh_);
            if (!bvh_) bvh_ = std::make_unique<ParticleBvh>(*device_, settings_.geometry, settings_.gpu);
        }
        bvh_->build(particles, camera);
    }
    stats.bvh = bvh_->stats();

    // Light sampler: only the power and tree estimators need one, and only with light.
    AliasTable powerTable;
    LightTree lightTree;
    double totalLuminance = 0.0;
    for (const Vec3& I : particles.emission) totalLuminance += luminance(I);
    const bool lit = totalLuminance > 0.0 && glm::length(settings_.shading.albedo) > 0.0f;
    const bool power = lit && needsPowerTable(settings_.render);
    const bool tree = lit && needsLightTree(settings_.render);
    if (power || tree) {
        auto t = timer.scope(pass::buildLightSampler);
        if (power) powerTable = buildPowerTable(particles);
        if (tree) lightTree = LightTree(particles, settings_.shading);
        stats.lightTreeNodes = lightTree.nodeCount();
    }

    GBuffer gbuffer;
    {
        auto t = timer.scope(pass::traceGBuffer);
        stats.primaryRays = traceGBuffer(*bvh_, particles, camera, settings_.shading.model, gbuffer);
    }

    FrameImage img;
    img.width = camera.width;
    img.height = camera.height;
    const std::size_t pixels = std::size_t(img.width) * img.height;
    {
        auto t = timer.scope(pass::estimateLighting);
        if (lit && restir_) {
            RestirInputs in{*bvh_, particles, gbuffer, camera, settings_, frame, power ? &powerTable : nullptr,
                            previousBvh_.get()};
            stats.lighting = restir_->render(in, img.lighting, img.reservoirs, timer);
            stats.reservoirBytes = restir_->reservoirBytes();
        } else if (lit) {
            Progress progress(fmt::format("frame {} {}", frame, pass::estimateLighting), pixels, options_.quiet);
            LightingInputs in{*bvh_, particles, gbuffer, settings_.shading, settings_.render, frame,
                              power ? &powerTable : nullptr, tree ? &lightTree : nullptr};
            stats.lighting = estimateLighting(in, img.lighting, &progress);
        } else {
            img.lighting.Lr.assign(pixels, Vec3(0.0f));
            img.lighting.Lr_stderr.assign(pixels, Vec3(0.0f));
            img.lighting.spp.assign(pixels, 0.0f);
        }
    }
    {
        auto t = timer.scope(pass::composeImage);
        img.L.resize(pixels);
        img.Le.assign(pixels, Vec3(0.0f));
        img.depth.resize(pixels);
        img.normal.resize(pixels);
        img.particle.resize(pixels);
        const float se = static_cast<float>(settings_.shading.self_emission);
        std::size_t hits = 0;
        for (std::size_t px = 0; px < pixels; ++px) {
            const GBufferTexel& g = gbuffer.texels[px];
            img.particle[px] = g.particle;
            if (!g.hit()) {
                img.L[px] = settings_.shading.background;
                img.depth[px] = std::numeric_limits<float>::infinity();
                img.normal[px] = Vec3(0.0f);
                continue;
            }
            ++hits;
            img.Le[px] = se * particles.emission[g.particle];
            img.L[px] = img.Le[px] + img.lighting.Lr[px];
            img.depth[px] = g.depth;
            img.normal[px] = g.normal;
        }
        stats.hitPixels = hits;
        double sppSum = 0.0;
        for (std::size_t px = 0; px < pixels; ++px)
            if (gbuffer.texels[px].hit()) {
                sppSum += img.lighting.spp[px];
                stats.maxSpp = std::max(stats.maxSpp, double(img.lighting.spp[px]));
            }
        stats.meanSpp = hits ? sppSum / double(hits) : 0.0;
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return img;
}

}  // namespace accretion
