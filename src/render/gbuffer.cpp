#include "accretion/render/gbuffer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "accretion/geometry/billboard.h"
#include "accretion/gpu/gpu_layouts.h"

namespace accretion {

namespace {

template <bool Count>
void trace(const ParticleBvh& bvh, const Particles& particles, const Camera& camera, ShadingModel model,
           GBuffer& gbuffer, PassCounters* counters) {
    const bool spheres = bvh.settings().primitive == Primitive::sphere;

    // One G-buffer texel from a primary hit.
    auto fill = [&](std::size_t px, const Vec3& dir, const SurfaceHit& hit) {
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
    };

    // 8x8 tiles at fixed positions, so that the packets (tile rows) do not
    // depend on how the work is split between threads.
    const std::uint32_t tilesX = (camera.width + 7) / 8, tilesY = (camera.height + 7) / 8;
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, tilesX * tilesY), [&](const auto& tiles) {
        for (std::uint32_t tile = tiles.begin(); tile != tiles.end(); ++tile) {
            const std::uint32_t x0 = (tile % tilesX) * 8, yEnd = std::min(camera.height, (tile / tilesX) * 8 + 8);
            const int n = int(std::min<std::uint32_t>(8, camera.width - x0));
            // Packets of 8 coherent pixel rays make the image, in both modes.
            for (std::uint32_t y = (tile / tilesX) * 8; y < yEnd; ++y) {
                Vec3 dirs[8];
                SurfaceHit hits[8];
                bool found[8];
                for (int k = 0; k < n; ++k) dirs[k] = camera.pixelDirection(x0 + k, y);
                bvh.intersect8(camera.position, dirs, n, hits, found);
                for (int k = 0; k < n; ++k) {
                    const std::size_t px = std::size_t(y) * camera.width + x0 + k;
                    if (found[k]) fill(px, dirs[k], hits[k]);
                    if constexpr (Count) {
                        // The counters come from the ray a GPU thread traces: one
                        // ray through the counting TLAS (its hit is the same).
                        Recorder<true> rec(&counters->threads[px]);
                        RayCounters rc;
                        SurfaceHit single;
                        bvh.intersect(camera.position, dirs[k], std::numeric_limits<float>::infinity(), single, &rc);
                        rec.ray(rc);
                        rec.write(gpu_layout::kGBufferTexel);
                        if (!found[k]) continue;
                        rec.shade(true, particles.type[hits[k].particle], hits[k].cluster);
                        rec.read(gpu_layout::kParticleRecord);
                    }
                }
            }
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
