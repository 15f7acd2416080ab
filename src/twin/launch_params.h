#pragma once
// What every OptiX program and CUDA kernel of the twin reads: one struct,
// copied to the device per launch. Host and device see the same layout.
#include <cstdint>

#include <optix_types.h>

#include "accretion/geometry/billboard.h"
#include "accretion/lighting/light_tree_view.h"
#include "accretion/lighting/source_pmf.h"
#include "accretion/lighting/reservoir_codec.h"
#include "accretion/render/accumulation.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/render/particle_split_passes.h"
#include "accretion/render/restir_passes.h"
#include "accretion/render/voxel_cache_passes.h"
#include "accretion/render/shadow_query.h"
#include "accretion/scene/settings.h"

namespace accretion::twin {

/// Ray types (SBT hit-group records per geometry: stride 2).
enum RayType : unsigned { kPrimaryRay = 0, kShadowRay = 1, kRayTypes = 2 };

/// Counters of one launch, summed with one atomic per thread.
struct LaunchCounters {
    unsigned long long rays = 0;         ///< shadow rays (optixTrace / optixTraverse calls)
    unsigned long long anyHits = 0;      ///< any-hit invocations
    unsigned long long occluded = 0;     ///< shadow rays that found a blocker
    unsigned long long lightTerms = 0;   ///< unshadowed terms evaluated
    unsigned long long retests = 0;      ///< shadow rays traced again past an excluded billboard (opacity micromaps)
};

/// The lights of one frame as the restir passes read them (this frame's, or
/// the previous frame's for temporal reuse): frame coordinates of that frame.
struct LightView {
    std::uint32_t count = 0;
    float uniformPdf = 0.0f;             ///< 1 / count, rounded as LightArrays does
    const Vec3* position = nullptr;
    const Vec3* emission = nullptr;
    const Vec3* albedo = nullptr;
    const float* dmin2 = nullptr;        ///< max(r_i, dmin)^2
};

/// uniform and power (docs/MODEL.md section 4) as the CPU runs them, one
/// pixel per thread: the CPU's LightingPlan (chunks of up to 8 samples, each
/// chunk its own stream; adaptive sampling stops a pixel at the end of a round).
struct SamplingParams {
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
    LightingPlan plan;                   ///< planLighting of the frame (the whole frame: no shard)
    std::uint32_t maxSamples = 65536;
    double targetStderr = 0.0;
    bool discardNonFinite = false;       ///< render.nonfinite = discard
    Vec3* Lr_stderr = nullptr;           ///< width x height, as Lr
    float* spp = nullptr;
    std::uint32_t* rejected = nullptr;
};

/// ReSTIR DI (docs/MODEL.md section 4) as the CPU's passes run it.
struct RestirParams {
    /// The passes' settings and the lighting grid every restir pass runs on:
    /// the image at restir.resolution_scale (the image itself at 1).
    restir::ReuseParams reuse;
    const GBufferTexel* gbuffer = nullptr;  ///< the lighting grid's G-buffer
    Vec3* Lr = nullptr;                     ///< and its Lr
    bool temporal = false;               ///< a history exists and temporal reuse is on
    BiasCorrection bias = BiasCorrection::basic;
    bool visibilityReuse = false;
    bool discardNonFinite = false;       ///< render.nonfinite = discard
    bool reorder = false;                ///< shadeTraverse: optixReorder by the SER key first
    std::uint32_t serHintBits = 0;       ///< the SER key's hint bits (the light's cluster)
    const StoredReservoir* in = nullptr; ///< the pass's input reservoirs
    StoredReservoir* out = nullptr;      ///< its output
    std::uint32_t* rejected = nullptr;   ///< per pixel: non-finite values rejected
    // The previous frame (temporal reuse).
    LightView prevLights;
    const GBufferTexel* prevGbuffer = nullptr;  ///< the previous lighting grid's
    const StoredReservoir* prevReservoirs = nullptr;
    Camera prevCamera;
    const std::uint32_t* particleCluster = nullptr; ///< BLAS of each particle (SER hint)
    // particle_restir: the lighting grid (gbuffer, Lr, reuse) is the visible
    // particles' texels (particle_texels.h); the pixels read them at the end.
    const std::uint32_t* slotOf = nullptr;      ///< particle -> slot this frame (kNoSlot: not visible)
    const std::uint32_t* prevSlotOf = nullptr;  ///< last frame's
    std::uint32_t prevSlotCount = 0;            ///< particles prevSlotOf holds
    const Vec3* prevTexelLr = nullptr;          ///< restir.texel_history: last frame's texel Lr
};

/// voxel_cache (voxel_cache_passes.h) as the CPU's VoxelCache runs it: the
/// cells read (last frame's in updateVoxelCache, this frame's in
/// shadeVoxelPixels) and written, double-buffered so that a timed pass
/// run again computes the same cells; each cell's rays, traced one a
/// thread, then summed per cell in order.
struct VoxelLaunch {
    voxel::VoxelParams params;
    const std::uint8_t* occupied = nullptr;  ///< per cell: a particle reaches it
    const voxel::VoxelCell* read = nullptr;
    voxel::VoxelCell* write = nullptr;
    voxel::CellRay* rays = nullptr;          ///< cell c's ray r at c x params.rays + r
};

/// particle_split (particle_split_passes.h) as the CPU's ParticleSplit runs
/// it: the visible particles' texels (gatherParticleTexels' grid), their
/// near lights, the texels' Lr, and last frame's by particle id.
struct SplitLaunch {
    psplit::SplitParams params;
    const std::uint32_t* particleOf = nullptr;  ///< slot -> particle (the gather's sorted ids)
    const std::uint64_t* lightPath = nullptr;   ///< each light's path in the light tree (LightTree::paths)
    const std::uint32_t* slotOf = nullptr;      ///< particle -> slot (kNoSlot: not visible)
    const GBufferTexel* texels = nullptr;       ///< the grid, kTexelRowWidth a row
    std::uint32_t* near = nullptr;              ///< slot v's near lights at v x params.nearCount (kNoNearLight past its count)
    std::uint32_t* nearFound = nullptr;
    float* nearRadius2 = nullptr;
    psplit::SplitRay* rays = nullptr;           ///< texel q's ray r at r x rayStride + q (whichever thread traced it; far_new's past near + far)
    std::size_t rayStride = 0;                  ///< the grid's texels: ray r of every texel at r x rayStride
    bool texelMajor = false;                    ///< threads texel by texel within each kind of ray (twin --ray-launch texels)
    std::uint32_t* newTexels = nullptr;         ///< particle_split.far_new: the texels without history, in order (their extra rays' threads)
    Vec3* texelLr = nullptr;
    std::uint32_t* rejected = nullptr;          ///< per texel: non-finite far draws
    const std::uint32_t* prevSlotOf = nullptr;  ///< particle_split.history: last frame's slots
    std::uint32_t prevSlotCount = 0;            ///< particles prevSlotOf holds (0: no history)
    const Vec3* prevTexelLr = nullptr;
    Vec3* texelFar = nullptr;                   ///< particle_split.history_of far: the texels' far means' average
    const Vec3* prevTexelFar = nullptr;         ///< and last frame's
    std::uint32_t* texelAge = nullptr;          ///< particle_split.history_start mean: the far rays (frames) each texel has averaged
    const std::uint32_t* prevTexelAge = nullptr;  ///< and last frame's
    const std::uint32_t* prevNear = nullptr;      ///< particle_split.far_handoff: last frame's near lights by its slots (as near)
    const std::uint32_t* prevNearFound = nullptr;
    Vec3* texelNear = nullptr;                    ///< the texels' near terms, texel q's m at q x params.nearCount + m
    const Vec3* prevTexelNear = nullptr;          ///< and last frame's
};

struct LaunchParams {
    OptixTraversableHandle tlas = 0;
    Camera camera;                       ///< frame coordinates (origin at the first camera)
    ShadingModel model = ShadingModel::lambert;
    bool discAlpha = false;              ///< the disc alpha test (any-hit) on every ray
    bool shadows = true;                 ///< shading.visibility
    VisibilityOptions visibility;        ///< render.visibility_rule and its offsets
    bool omm = false;                    ///< BLAS with opacity micromaps (shadow rays re-test excluded hits)

    // Particles, frame coordinates (struct-of-arrays, as on the CPU).
    std::uint32_t particleCount = 0;
    const Vec3* position = nullptr;
    const Vec3* emission = nullptr;
    const Vec3* albedo = nullptr;
    const float* radius = nullptr;
    const float* dmin2 = nullptr;        ///< max(r_i, dmin)^2
    const BillboardFrame* frames = nullptr;

    // The layout (geometry.layout). clusters and aabbs: BLAS c (TLAS
    // instance id c) holds particles clusterParticle[clusterOffset[c] ..],
    // two triangles, one sphere or one box each; instances: instance id i is
    // particle i, its BLAS the unit billboard's two triangles.
    AccelLayout layout = AccelLayout::clusters;
    bool spheres = false;                ///< built-in spheres (geometry.primitive = sphere)
    const std::uint32_t* clusterParticle = nullptr;
    const std::uint32_t* clusterOffset = nullptr;

    LightView lights;                    ///< this frame's lights (the same arrays as above)
    SourcePmf source;                    ///< power's lights and restir's candidates (render.source) of this frame
    LightTreeView tree;                  ///< render.source = "tree": the CPU's light tree (nodes null otherwise)
    SamplingParams sampling;
    RestirParams restir;
    VoxelLaunch voxel;
    SplitLaunch split;

    // Outputs.
    GBufferTexel* gbuffer = nullptr;     ///< width x height
    Vec3* Lr = nullptr;                  ///< width x height
    LaunchCounters* counters = nullptr;  ///< null: not counted (timed launches: the atomics would be timed too)
};

/// The particle of a hit: its instance and primitive, by the layout.
ACC_HD inline std::uint32_t hitParticle(const LaunchParams& p, unsigned instance, unsigned primitive) {
    if (p.layout == AccelLayout::instances) return instance;
    const unsigned slot = p.layout == AccelLayout::clusters && !p.spheres ? primitive >> 1 : primitive;
    return p.clusterParticle[p.clusterOffset[instance] + slot];
}

}  // namespace accretion::twin
