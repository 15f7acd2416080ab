#pragma once
#include <cstdint>
#include <limits>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/geometry/camera.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/render/pixel_window.h"

namespace accretion {

/// The primary hits of a window of the image (traceGBuffer's: a crop's, or
/// the whole image), row by row: a crop holds and touches its own pixels
/// alone. A pixel's streams are still keyed by its index in the whole image.
struct GBuffer {
    std::uint32_t width = 0, height = 0;  ///< the image's
    PixelWindow window;                   ///< the pixels held
    std::vector<GBufferTexel> texels;     ///< window.pixels() texels
    const GBufferTexel& at(std::uint32_t x, std::uint32_t y) const { return texels[window.index(x, y)]; }
    bool whole() const { return window.isWhole(width, height); }
};

/// The shading point of a hit texel.
[[gnu::always_inline]] inline ShadingPoint shadingPoint(const GBufferTexel& g, const Particles& particles) {
    const Vec3 centre = particles.position[g.particle];
    return {centre + g.local, g.normal, g.geomNormal, particles.albedo[g.particle], g.particle, centre, g.local};
}

/// Counting mode: a pixel thread that reads texel g, with its branch key
/// (hit, particle type) and cluster.
inline void recordTexel(ThreadCounters& t, const GBufferTexel& g, const Particles& particles, const ParticleBvh& bvh,
                        std::uint32_t texelBytes) {
    t.active = 1;
    t.bytesRead += texelBytes;
    if (!g.hit()) return;
    t.hit = 1;
    t.type = particles.type[g.particle];
    t.cluster = bvh.clusterOf(g.particle);
}

/// traceGBuffer: one primary ray per pixel through its centre (docs/MODEL.md
/// section 3). Returns the number of rays traced. With counters (counting
/// mode), records each pixel's thread: hit key, the ray, bytes. With a
/// window, only its pixels are traced and held (each as in the whole image).
std::uint64_t traceGBuffer(const ParticleBvh& bvh, const Particles& particles, const Camera& camera,
                           ShadingModel model, GBuffer& gbuffer, PassCounters* counters = nullptr,
                           const PixelWindow* window = nullptr);

}  // namespace accretion
