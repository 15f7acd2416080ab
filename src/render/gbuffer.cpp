#include "accretion/render/gbuffer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "accretion/geometry/billboard.h"
#include "accretion/core/error.h"
#include "accretion/counters/gpu_layouts.h"

namespace accretion {

namespace {

template <bool Count>
void trace(const ParticleBvh& bvh, const Particles& particles, const Camera& camera, ShadingModel model,
           const PixelWindow& window, GBuffer& gbuffer, PassCounters* counters) {
    const bool spheres = bvh.settings().primitive == Primitive::sphere;

    // One G-buffer texel from a primary hit (gbuffer_texel.h: shared with the OptiX twin).
    auto fill = [&](std::size_t slot, std::uint32_t x, std::uint32_t y, const Vec3& dir, const SurfaceHit& hit) {
        const std::uint32_t j = hit.particle;
        gbuffer.texels[slot] = spheres ? sphereTexel(camera, x, y, dir, j, particles.position[j], particles.radius[j], hit.t)
                                     : billboardTexel(camera, x, y, dir, j, particles.position[j], particles.radius[j],
                                                      bvh.frame(j), hit.uv, model);
    };

    // 8x8 tiles at fixed positions, so that the packets (tile rows) do not
    // depend on how the work is split between threads, nor on the window:
    // a window traces the whole packets of its tiles' rows and keeps its own
    // pixels, so that each is the pixel of the whole image.
    const std::uint32_t tx0 = window.x0 / 8, ty0 = window.y0 / 8;
    const std::uint32_t tilesX = (window.x1 + 7) / 8 - tx0, tilesY = (window.y1 + 7) / 8 - ty0;
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, tilesX * tilesY), [&](const auto& tiles) {
        for (std::uint32_t tile = tiles.begin(); tile != tiles.end(); ++tile) {
            const std::uint32_t x0 = (tx0 + tile % tilesX) * 8, tileY = (ty0 + tile / tilesX) * 8;
            const std::uint32_t yEnd = std::min(window.y1, tileY + 8);
            const int n = int(std::min<std::uint32_t>(8, camera.width - x0));
            // Packets of 8 coherent pixel rays make the image, in both modes.
            for (std::uint32_t y = std::max(window.y0, tileY); y < yEnd; ++y) {
                Vec3 dirs[8];
                SurfaceHit hits[8];
                bool found[8];
                for (int k = 0; k < n; ++k) dirs[k] = camera.pixelDirection(x0 + k, y);
                bvh.intersect8(camera.position, dirs, n, hits, found);
                for (int k = 0; k < n; ++k) {
                    if (!window.contains(x0 + k, y)) continue;
                    const std::size_t slot = window.index(x0 + k, y);
                    if (found[k]) fill(slot, x0 + k, y, dirs[k], hits[k]);
                    else gbuffer.texels[slot] = GBufferTexel{};
                    if constexpr (Count) {
                        // The counters come from the ray a GPU thread traces: one
                        // ray through the counting TLAS (its hit is the same).
                        Recorder<true> rec(&counters->threads[std::size_t(y) * camera.width + x0 + k]);
                        RayCounters rc;
                        SurfaceHit single;
                        bvh.intersect(camera.position, dirs[k], std::numeric_limits<float>::infinity(), single, &rc);
                        rc.misses = found[k] ? 0u : 1u;
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
                           ShadingModel model, GBuffer& gbuffer, PassCounters* counters, const PixelWindow* window) {
    gbuffer.width = camera.width;
    gbuffer.height = camera.height;
    const PixelWindow w = window ? *window : PixelWindow::whole(camera.width, camera.height);
    ACC_CHECK(w.x0 < w.x1 && w.x1 <= camera.width && w.y0 < w.y1 && w.y1 <= camera.height);
    ACC_CHECK(!counters || w.isWhole(camera.width, camera.height));  // the GPU's dispatch is the whole frame
    gbuffer.window = w;
    gbuffer.texels.resize(w.pixels());  // every texel is written by the trace
    if (counters) trace<true>(bvh, particles, camera, model, w, gbuffer, counters);
    else trace<false>(bvh, particles, camera, model, w, gbuffer, nullptr);
    return w.pixels();
}

}  // namespace accretion
