// gatherParticleTexels: particle_restir's lighting grid from the frame's G-buffer.
#include "accretion/render/particle_texel_grid.h"

#include <algorithm>
#include <utility>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "accretion/counters/gpu_layouts.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/particles/particles.h"

namespace accretion {

ParticleTexels gatherParticleTexels(const GBuffer& gbuffer, const Particles& particles, const ParticleBvh& bvh,
                                    const Camera& camera, ShadingModel model, std::uint32_t side, std::uint32_t layers,
                                    const TexelPointRule& points) {
    ParticleTexels t;
    t.side = side;
    t.layers = layers;
    const std::size_t n = particles.size();

    // The particles some pixel sees.
    std::vector<std::uint8_t> seen(n, 0);
    for (const GBufferTexel& g : gbuffer.texels)
        if (g.hit()) seen[g.particle] = 1;
    std::vector<std::uint32_t> visible;
    for (std::uint32_t j = 0; j < n; ++j)
        if (seen[j]) visible.push_back(j);

    // Morton order over the particles' bounding cube, ties by id.
    const MortonFrame frame = mortonFrame(particles.position.data(), n);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(visible.size());
    tbb::parallel_for(std::size_t(0), visible.size(), [&](std::size_t k) {
        const std::uint32_t j = visible[k];
        keyed[k] = {frame.key(particles.position[j]), j};
    });
    tbb::parallel_sort(keyed.begin(), keyed.end());

    t.particleOf.resize(keyed.size());
    t.slotOf.assign(n, kNoSlot);
    for (std::uint32_t v = 0; v < keyed.size(); ++v) {
        t.particleOf[v] = keyed[v].second;
        t.slotOf[keyed[v].second] = v;
    }

    // The texels, kTexelRowWidth a row.
    const std::uint32_t per = t.perParticle(), perLayer = t.side * t.side;
    const std::size_t count = t.texels();
    t.grid.width = kTexelRowWidth;
    t.grid.height = std::uint32_t((count + kTexelRowWidth - 1) / kTexelRowWidth);
    t.grid.window = PixelWindow::whole(t.grid.width, t.grid.height);
    t.grid.texels.assign(std::size_t(t.grid.width) * t.grid.height, GBufferTexel{});
    tbb::parallel_for(std::uint32_t(0), t.visible(), [&](std::uint32_t v) {
        const std::uint32_t j = t.particleOf[v];
        const BillboardFrame& f = bvh.frame(j);
        for (std::uint32_t s = 0; s < perLayer; ++s) {
            const GBufferTexel g = billboardPointTexel(camera, j, particles.position[j], particles.radius[j], f,
                                                          texelPointUv(j, s, t.side, points), model);
            for (std::uint32_t k = 0; k < t.layers; ++k) t.grid.texels[std::size_t(v) * per + k * perLayer + s] = g;
        }
    });
    return t;
}

std::uint64_t gatherItemSteps(std::size_t particles, const ParticleTexels& texels) {
    return 2 * std::uint64_t(particles) + (3 + kSortDigitPasses) * std::uint64_t(texels.visible()) + texels.grid.texels.size();
}

void recordGatherParticleTexels(const GBuffer& gbuffer, const Particles& particles, const ParticleBvh& bvh, const ParticleTexels& texels,
                                PassCounters& pc) {
    for (std::size_t px = 0; px < gbuffer.texels.size(); ++px) {
        ThreadCounters& t = pc.threads[px];
        recordTexel(t, gbuffer.texels[px], particles, bvh, gpu_layout::kGBufferTexel);
        if (gbuffer.texels[px].hit()) t.bytesWritten += 1;
    }
    pc.itemSteps = gatherItemSteps(particles.size(), texels);
    pc.dispatches = kGatherDispatches;
}

}  // namespace accretion
