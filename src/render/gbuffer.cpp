#include "accretion/render/gbuffer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include "accretion/geometry/billboard.h"
#include "accretion/gpu/gpu_layouts.h"

namespace accretion {

namespace {

template <bool Count>
void trace(const ParticleBvh& bvh, const Particles& particles, const Camera& camera, ShadingModel model,
           GBuffer& gbuffer, PassCounters* counters) {
    const bool spheres = bvh.settings().primitive == Primitive::sphere;

    tbb::parallel_for(tbb::blocked_range2d<std::uint32_t>(0, camera.height, 8, 0, camera.width, 8), [&](const auto& r) {
        for (std::uint32_t y = r.rows().begin(); y != r.rows().end(); ++y)
            for (std::uint32_t x = r.cols().begin(); x != r.cols().end(); ++x) {
                const std::size_t px = std::size_t(y) * camera.width + x;
                const Vec3 dir = camera.pixelDirection(x, y);
                SurfaceHit hit;
                Recorder<Count> rec(Count ? &counters->threads[px] : nullptr);
                RayCounters rc;
                const bool found =
                    bvh.intersect(camera.position, dir, std::numeric_limits<float>::infinity(), hit, rec.rayCounters(rc));
                rec.ray(rc);
                rec.write(gpu_layout::kGBufferTexel);
                if (!found) continue;
                rec.shade(true, particles.type[hit.particle], hit.cluster);
                rec.read(gpu_layout::kParticleRecord);
                GBufferTexel& g = gbuffer.texels[px];
                const std::uint32_t j = hit.particle;
                const Vec3 p = particles.position[j];
                const float rj = particles.radius[j];
                g.particle = j;
                if (spheres) {
                    // Re-project onto the sphere: accurate to the centre's precision.
                    Vec3 n = camera.position + hit.t * dir - p;
                    const float len = glm::length(n);
                    n = len > 0.0f ? n / len : -dir;
                    g.position = p + rj * n;
                    g.normal = g.geomNormal = n;
                    g.uv = Vec2(0.5f + 0.5f * glm::dot(n, camera.right), 0.5f + 0.5f * glm::dot(n, camera.up));
                } else {
                    // On the quad from uv: error relative to |p|, not to the ray length.
                    const BillboardFrame& f = bvh.frame(j);
                    g.uv = hit.uv;
                    g.position = p + ((2.0f * hit.uv.x - 1.0f) * rj) * f.right + ((2.0f * hit.uv.y - 1.0f) * rj) * f.up;
                    g.geomNormal = glm::normalize(f.normal());
                    if (glm::dot(g.geomNormal, dir) > 0.0f) g.geomNormal = -g.geomNormal;
                    g.normal = model == ShadingModel::sphere ? impostorNormal(f, hit.uv) : g.geomNormal;
                }
                g.depth = glm::dot(g.position - camera.position, camera.forward);
            }
    });
}

}  // namespace

std::uint64_t traceGBuffer(const ParticleBvh& bvh, const Particles& particles, const Camera& camera,
                           ShadingModel model, GBuffer& gbuffer, PassCounters* counters) {
    gbuffer.width = camera.width;
    gbuffer.height = camera.height;
    gbuffer.texels.assign(std::size_t(camera.width) * camera.height, GBufferTexel{});
    if (counters) trace<true>(bvh, particles, camera, model, gbuffer, counters);
    else trace<false>(bvh, particles, camera, model, gbuffer, nullptr);
    return std::uint64_t(camera.width) * camera.height;
}

}  // namespace accretion
