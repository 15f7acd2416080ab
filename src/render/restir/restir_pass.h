#pragma once
// What the restir passes share (internal to src/render/restir/): the frame
// context, the offers a pass resamples, pixel loops and counting helpers.
#include <cmath>
#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>


#include "accretion/core/rng.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_tiles.h"
#include "accretion/lighting/regir_grid.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/particle_texel_grid.h"
#include "accretion/render/restir.h"
#include "accretion/render/visibility.h"

namespace accretion {

/// The previous frame as temporal reuse sees it.
struct Restir::History {
    GBuffer gbuffer;                        ///< lighting-resolution G-buffer
    Particles particles;                    ///< previous positions / emission / albedo
    LightArrays lights;                     ///< views of `particles`
    Camera camera;
    std::vector<StoredReservoir> reservoirs;
    /// particle_restir: the slot of each particle visible last frame (kNoSlot otherwise).
    std::vector<std::uint32_t> slotOf;
    std::vector<Vec3> texelLr;  ///< particle_restir with texel_history: each texel's Lr (after its average)
};

namespace restir {

/// The domain of a reservoir: the receiver and the lights its p_hat used,
/// and whether its samples passed a visibility test (then its support is
/// that of p_hat x V, and basic_visibility must test V to count it).
struct Domain {
    ShadingPoint sp;
    const LightArrays* lights;
    bool visibilityTested = false;
    const ParticleBvh* bvh = nullptr;  ///< the geometry of the domain's frame (visibility tests)
};

/// A reservoir offered for resampling at the current pixel.
struct Offer {
    StoredReservoir r;
    Domain domain;
};

/// Per-thread buffers of a resampling pass, sized by the neighbours asked for.
struct Scratch {
    std::vector<Offer> offers;
};

/// A tile of a pass's grid: columns [x0, x1), rows [y0, y1).
struct PixelTile {
    std::uint32_t x0, x1, y0, y1;
};

/// The pixel passes' one parallel loop, compiled once (pixel_tiles.cpp):
/// tile(t, counters, scratch) over the w x h grid in 8x8 tiles on every
/// core, each thread with its own counters and scratch; returns the
/// counters summed (integers: the same whatever the threads). Instantiated
/// in each of the 60 kernels of a pass file, TBB's loop and thread-local
/// state had been two fifths of their code and compile time.
LightingCounters runPixelTiles(std::uint32_t w, std::uint32_t h,
                               const std::function<void(const PixelTile&, LightingCounters&, Scratch&)>& tile);

/// Runs body(px, x, y, counters) or body(px, x, y, counters, scratch) over
/// the pixels of a w x h grid in 8x8 tiles; counters and scratch are the
/// running thread's.
template <class Body>
LightingCounters forEachPixel(std::uint32_t w, std::uint32_t h, Body&& body) {
    return runPixelTiles(w, h, [&](const PixelTile& t, LightingCounters& c, Scratch& s) {
        for (std::uint32_t y = t.y0; y != t.y1; ++y)
            for (std::uint32_t x = t.x0; x != t.x1; ++x) {
                if constexpr (std::is_invocable_v<Body&, std::size_t, std::uint32_t, std::uint32_t, LightingCounters&, Scratch&>)
                    body(std::size_t(y) * w + x, x, y, c, s);
                else
                    body(std::size_t(y) * w + x, x, y, c);
            }
    });
}

struct FrameContext {
    const RestirInputs& in;
    const RestirSettings& rs;
    const ReservoirCodec& codec;
    const GBuffer& lg;          ///< lighting-resolution G-buffer
    const LightArrays& L;
    const Restir::History* prev;
    float scale;                ///< lighting / image resolution
    VisibilityOptions vis;      ///< render.visibility_rule
    bool shadows;               ///< plan.shadowRays: trace shadow rays (off: V = 1)
    FrameCounters* counters;    ///< counting mode: per-pass thread records
    std::uint32_t* rejected;    ///< per lighting texel: non-finite values rejected (render.nonfinite)
    /// The lighting grid as a window of the frame's (restir.crop_margin; ReuseParams).
    std::uint32_t wholeWidth = 0, originX = 0, originY = 0;
    /// The texels whose reuse offers are counted (stats' reuse): render.crop's
    /// on a window of the frame, not its margin's; else every texel.
    PixelWindow counted{0, ~0u, 0, ~0u};
    const LightTiles* tiles = nullptr;  ///< render.source tiles or regir: this frame's presampled tiles
    const RegirGrid* regir = nullptr;   ///< render.source regir: this frame's grid
    /// particle_restir: this frame's particle texels (lg is their grid, or
    /// the image's G-buffer in shadeParticlePixels and resampleParticlePixels).
    const ParticleTexels* texels = nullptr;

    /// Count a non-finite value at px; true if the policy discards the reservoir.
    bool reject(std::size_t px, LightingCounters& c) const {
        ++c.nonFinite;
        ++rejected[px];
        return in.settings.render.nonfinite == NonFinitePolicy::discard;
    }
};

/// The counters of a pass about to run (counting mode), else null.
template <bool Count>
PassCounters* passCounters(const FrameContext& f, Pass pass) {
    if constexpr (Count) return &f.counters->add(pass, f.lg.width, f.lg.height);
    return nullptr;
}

template <bool Count>
Recorder<Count> recorder(PassCounters* pc, std::size_t px) {
    if constexpr (Count) return Recorder<true>(&pc->threads[px]);
    else return Recorder<false>(nullptr);
}

/// The branch key of a lighting-grid texel (counting mode).
template <bool Count>
void recordHit(Recorder<Count>& rec, const FrameContext& f, const GBufferTexel& g) {
    rec.read(gpu_layout::kGBufferTexel);
    if constexpr (Count)
        if (g.hit()) rec.shade(true, f.in.particles.type[g.particle], f.in.bvh.clusterOf(g.particle));
}

/// Calls fn.template operator()<SM, P, Count>() with the frame's shading
/// model, primitive and counting mode (each pass compiles every variant).
template <class Fn>
LightingCounters dispatchKernel(const FrameContext& f, Fn&& fn) {
    auto byPrimitive = [&]<ShadingModel SM>() {
        const bool spheres = f.in.bvh.settings().primitive == Primitive::sphere;
        if (f.counters)
            return spheres ? fn.template operator()<SM, Primitive::sphere, true>()
                           : fn.template operator()<SM, Primitive::billboard, true>();
        return spheres ? fn.template operator()<SM, Primitive::sphere, false>()
                       : fn.template operator()<SM, Primitive::billboard, false>();
    };
    switch (f.in.settings.shading.model) {
    case ShadingModel::lambert: return byPrimitive.template operator()<ShadingModel::lambert>();
    case ShadingModel::sphere: return byPrimitive.template operator()<ShadingModel::sphere>();
    case ShadingModel::isotropic: return byPrimitive.template operator()<ShadingModel::isotropic>();
    }
    return {};
}

// The passes, in the order a frame runs them (one file each).
LightTiles presampleLightTiles(const FrameContext& f);
RegirGrid presampleRegirGrid(const FrameContext& f);
LightingCounters generateCandidates(const FrameContext& f, std::vector<StoredReservoir>& out);
LightingCounters temporalResampling(const FrameContext& f, const std::vector<StoredReservoir>& cur,
                                    std::vector<StoredReservoir>& out);
LightingCounters spatialResampling(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                   std::vector<StoredReservoir>& out);
LightingCounters traceShadowRays(const FrameContext& f, std::vector<StoredReservoir>& res, std::vector<Vec3>& Lr);
// particle_restir's own passes (particle_space.cpp): temporal reuse by
// particle id, spatial reuse among world neighbours, and the pixels read
// from the texels (f.lg the image's G-buffer, f.texels the texels).
LightingCounters temporalResamplingById(const FrameContext& f, const std::vector<StoredReservoir>& cur,
                                        std::vector<StoredReservoir>& out);
LightingCounters resampleWorldNeighbours(const FrameContext& f, std::uint32_t iteration, const std::vector<StoredReservoir>& cur,
                                        std::vector<StoredReservoir>& out);
/// restir.texel_history: each texel's Lr averaged with its own last frame's (in place).
LightingCounters accumulateTexelLr(const FrameContext& f, std::vector<Vec3>& texelLr);
/// restir.pixel_shading interpolate: each pixel its particle's texels' Lr, bilinear.
LightingCounters shadeParticlePixels(const FrameContext& f, const std::vector<Vec3>& texelLr, std::vector<Vec3>& Lr);
/// restir.pixel_shading resample: each pixel resamples its particle's texels'
/// samples at its own point and traces its own shadow ray.
LightingCounters resampleParticlePixels(const FrameContext& f, const std::vector<StoredReservoir>& texelReservoirs,
                                        std::vector<Vec3>& Lr);
void upsampleLighting(const GBuffer& full, const GBuffer& lg, const Particles& particles, const std::vector<Vec3>& lowLr,
                      float scale, const RestirSettings& rs, std::vector<Vec3>& Lr);
/// Counting mode: upsampleLighting's per-pixel work.
void recordUpsample(const RestirInputs& in, const GBuffer& lightingGrid, PassCounters& pc);

}  // namespace restir
}  // namespace accretion
