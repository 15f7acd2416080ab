#pragma once
#include <array>
#include <type_traits>
#include <utility>
#include <string_view>

#include "accretion/scene/settings.h"

namespace accretion {

/// The light sampler buildLightSampler builds.
enum class LightSamplerKind { none, power, tree };

/// The passes that light a frame of an estimator (FramePlan).
enum class LightingPasses {
    perPixel,       ///< estimateLighting's per-pixel loop (exact, the samplers, ris, split)
    restir,         ///< restir's reservoir passes (Restir), on pixels or particle texels
    voxelCache,     ///< updateVoxelCache and shadeVoxelPixels (VoxelCache)
    particleSplit,  ///< findNearLights, shadeSplitTexels and shadeParticlePixels (ParticleSplit)
};

/// What an estimator of Lr is and what it needs: the one place the
/// settings' checks (scene_parser), the frame plan, the commands (converge,
/// bias, experiment, render's outputs, the twin) and `accretion estimators`
/// (docs/rendering.md's table) read it from. It lives in the scene layer so
/// that the settings' checks can read it.
struct EstimatorInfo {
    EstimatorKind kind;
    bool sums;                ///< sums every light (exact): no samples, no standard error
    LightSamplerKind sampler; ///< the light sampler it draws from itself (ris and restir: their render.source's)
    bool resampling;          ///< draws render.candidates candidates from render.source, keeps one by RIS
    bool reuse;               ///< state reused across pixels and frames (restir's reservoirs, the voxel cache, particle_split's texel history): history frames first, one estimate a pixel
    bool unbiased;            ///< converges to exact whatever its settings (restir: only with a bias correction)
    bool adaptive;            ///< render.target_stderr stops each pixel at its error
    bool twin;                ///< accretion-optix runs it
    bool nearField;           ///< sums each pixel's nearest render.near_lights lights exactly (0: the pilot chooses them)
    std::string_view summary;
    /// When it is unbiased, where not always (`accretion estimators`).
    std::string_view unbiasedWhen = "with a bias correction";
    /// The passes that light its frames.
    LightingPasses passes = LightingPasses::perPixel;

    /// Runs restir's passes (Restir).
    constexpr bool restirPasses() const { return passes == LightingPasses::restir; }
    /// Draws its lights from render.source (ris and restir's candidates, the voxel cache's rays).
    constexpr bool drawsFromSource() const { return resampling || passes == LightingPasses::voxelCache; }
};

inline constexpr std::array<EstimatorInfo, 10> kEstimators = {{
    {EstimatorKind::exact, true, LightSamplerKind::none, false, false, true, false, true, false,
     "every light i != j with its shadow ray: the reference"},
    {EstimatorKind::uniform, false, LightSamplerKind::none, false, false, true, true, true, false,
     "S lights drawn uniformly per pixel, with the standard error"},
    {EstimatorKind::power, false, LightSamplerKind::power, false, false, true, true, true, false,
     "S lights drawn by luminance (alias table), with the standard error"},
    {EstimatorKind::ris, false, LightSamplerKind::none, true, false, true, true, false, false,
     "S reservoirs of render.candidates candidates from render.source, one shadow ray each"},
    {EstimatorKind::restir, false, LightSamplerKind::none, true, true, false, false, true, false,
     "ReSTIR DI: RIS candidates, temporal and spatial reuse, one shadow ray", "with a bias correction",
     LightingPasses::restir},
    {EstimatorKind::tree, false, LightSamplerKind::tree, false, false, true, true, false, false,
     "S lights drawn from the light tree at the receiver, with the standard error"},
    {EstimatorKind::split, false, LightSamplerKind::tree, false, false, true, true, false, true,
     "the nearest lights summed, the far ones drawn from the light tree"},
    {EstimatorKind::particle_restir, false, LightSamplerKind::none, true, true, false, false, true, false,
     "ReSTIR DI on the visible particles' billboard texels (history by particle id, world-space neighbours); pixels interpolate or resample them",
     "pixel_shading resample, with a bias correction (interpolate: no)", LightingPasses::restir},
    {EstimatorKind::voxel_cache, false, LightSamplerKind::none, false, true, false, false, true, false,
     "seed 004's voxel radiance cache: lights from render.source at each occupied cell's centre, one shadow ray each, averaged over frames; pixels read it trilinearly",
     "never (the light at the cells' centres, in an L1 or cosine basis)", LightingPasses::voxelCache},
    {EstimatorKind::particle_split, false, LightSamplerKind::tree, false, true, false, false, true, false,
     "seed 004's hybrid compute on the visible particles' billboard texels: the nearest lights summed, far ones drawn from the light tree, a shadow ray each; pixels interpolate",
     "never (the light at the texels, not at the pixel)", LightingPasses::particleSplit},
}};

constexpr bool estimatorTableMatchesEnum() {
    for (std::size_t k = 0; k < kEstimators.size(); ++k)
        if (std::size_t(kEstimators[k].kind) != k) return false;
    return kEstimators.size() == EnumNames<EstimatorKind>::names.size();
}
static_assert(estimatorTableMatchesEnum(), "kEstimators lists every EstimatorKind in enum order");

constexpr const EstimatorInfo& estimatorInfo(EstimatorKind kind) { return kEstimators[std::size_t(kind)]; }

/// What a candidate source (render.source) of ris and restir is and needs:
/// the one place the settings' checks, the plan, generateCandidates' counters,
/// the GPU memory model and the twin read it from.
struct LightSourceInfo {
    LightSource kind;
    LightSamplerKind sampler; ///< the light sampler built for it (tiles and regir presample from the power table)
    /// Drawn from light tiles presampled once per frame (presampleLightTiles,
    /// a pass of restir's frame): restir only. ris, which averages many
    /// samples of one frame, would converge to that frame's draw.
    bool presampled;
    bool regirGrid;           ///< drawn from a world-space grid of reservoirs (presampleRegirGrid)
    bool twin;                ///< accretion-optix draws from it
};

inline constexpr std::array<LightSourceInfo, 5> kLightSources = {{
    {LightSource::uniform, LightSamplerKind::none, false, false, true},
    {LightSource::power, LightSamplerKind::power, false, false, true},
    {LightSource::tree, LightSamplerKind::tree, false, false, true},
    {LightSource::tiles, LightSamplerKind::power, true, false, false},  // RTXDI's light tiles, presampled by power
    {LightSource::regir, LightSamplerKind::power, true, true, false},   // ReGIR's grid of reservoirs, the tiles outside it
}};

constexpr bool sourceTableMatchesEnum() {
    for (std::size_t k = 0; k < kLightSources.size(); ++k)
        if (std::size_t(kLightSources[k].kind) != k) return false;
    return kLightSources.size() == EnumNames<LightSource>::names.size();
}
static_assert(sourceTableMatchesEnum(), "kLightSources lists every LightSource in enum order");

constexpr const LightSourceInfo& sourceInfo(LightSource kind) { return kLightSources[std::size_t(kind)]; }

/// fn.template operator()<K>() with K the `kind` of the row of `table`
/// (an array of rows with a member `kind`, in enum order) that matches: the
/// one dispatch of a runtime kind to the code compiled for it, so that a new
/// row is dispatched without a new case anywhere. fn returns void or a
/// default-constructible value.
template <const auto& table, class Kind, class Fn>
decltype(auto) withRow(Kind kind, Fn&& fn) {
    using R = decltype(fn.template operator()<table[0].kind>());
    return [&]<std::size_t... I>(std::index_sequence<I...>) -> R {
        if constexpr (std::is_void_v<R>) {
            ((kind == table[I].kind ? (fn.template operator()<table[I].kind>(), true) : false) || ...);
        } else {
            R r{};
            ((kind == table[I].kind ? (r = fn.template operator()<table[I].kind>(), true) : false) || ...);
            return r;
        }
    }(std::make_index_sequence<table.size()>{});
}

/// withRow over kEstimators: fn.template operator()<K>() for the estimator `kind`.
template <class Fn> decltype(auto) withEstimatorKind(EstimatorKind kind, Fn&& fn) {
    return withRow<kEstimators>(kind, std::forward<Fn>(fn));
}

/// withRow over kLightSources: fn.template operator()<S>() for the source `kind`.
template <class Fn> decltype(auto) withLightSource(LightSource kind, Fn&& fn) {
    return withRow<kLightSources>(kind, std::forward<Fn>(fn));
}

/// The light sampler a frame lit by `render`'s estimator needs: its own, or
/// its render.source's.
constexpr LightSamplerKind samplerFor(const RenderSettings& render) {
    const EstimatorInfo& e = estimatorInfo(render.estimator);
    return e.drawsFromSource() ? sourceInfo(render.source).sampler : e.sampler;
}

/// Whether render.crop traces, lights and holds its window alone (each pixel
/// as in the whole image): for every estimator without reuse (spatial reuse
/// reads the neighbours, history is the whole frame's), and not in counting
/// mode (the GPU's dispatch is the whole frame). FramePlan::traced and the
/// memory estimate of the settings read it.
constexpr bool cropRendersAlone(const Settings& s) { return !estimatorInfo(s.render.estimator).reuse && !s.gpu.counters; }

}  // namespace accretion
