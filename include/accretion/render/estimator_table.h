#pragma once
#include <array>
#include <string_view>

#include "accretion/scene/settings.h"

namespace accretion {

/// The light sampler buildLightSampler builds.
enum class LightSamplerKind { none, power, tree };

/// What an estimator of Lr is and what it needs: the one place the
/// settings' checks, the frame plan, the commands (converge, bias,
/// experiment, render's outputs, the twin) and `accretion estimators`
/// (docs/rendering.md's table) read it from.
struct EstimatorInfo {
    EstimatorKind kind;
    bool sums;                ///< sums every light (exact): no samples, no standard error
    LightSamplerKind sampler; ///< the light sampler it draws from itself (ris and restir: their render.source's)
    bool resampling;          ///< draws render.candidates candidates from render.source, keeps one by RIS
    bool reuse;               ///< reservoirs reused across pixels and frames: restir's passes and history
    bool unbiased;            ///< converges to exact whatever its settings (restir: only with a bias correction)
    bool adaptive;            ///< render.target_stderr stops each pixel at its error
    bool twin;                ///< accretion-optix runs it
    std::string_view summary;
};

inline constexpr std::array<EstimatorInfo, 7> kEstimators = {{
    {EstimatorKind::exact, true, LightSamplerKind::none, false, false, true, false, true,
     "every light i != j with its shadow ray: the reference"},
    {EstimatorKind::uniform, false, LightSamplerKind::none, false, false, true, true, true,
     "S lights drawn uniformly per pixel, with the standard error"},
    {EstimatorKind::power, false, LightSamplerKind::power, false, false, true, true, true,
     "S lights drawn by luminance (alias table), with the standard error"},
    {EstimatorKind::ris, false, LightSamplerKind::none, true, false, true, true, false,
     "S reservoirs of render.candidates candidates from render.source, one shadow ray each"},
    {EstimatorKind::restir, false, LightSamplerKind::none, true, true, false, false, true,
     "ReSTIR DI: RIS candidates, temporal and spatial reuse, one shadow ray"},
    {EstimatorKind::tree, false, LightSamplerKind::tree, false, false, true, true, false,
     "S lights drawn from the light tree at the receiver, with the standard error"},
    {EstimatorKind::split, false, LightSamplerKind::tree, false, false, true, true, false,
     "the nearest lights summed, the far ones drawn from the light tree"},
}};

constexpr bool estimatorTableMatchesEnum() {
    for (std::size_t k = 0; k < kEstimators.size(); ++k)
        if (std::size_t(kEstimators[k].kind) != k) return false;
    return kEstimators.size() == EnumNames<EstimatorKind>::names.size();
}
static_assert(estimatorTableMatchesEnum(), "kEstimators lists every EstimatorKind in enum order");

constexpr const EstimatorInfo& estimatorInfo(EstimatorKind kind) { return kEstimators[std::size_t(kind)]; }

/// The light sampler a frame lit by `render`'s estimator needs: its own, or
/// its render.source's (tiles and regir presample from the power table).
constexpr LightSamplerKind samplerFor(const RenderSettings& render) {
    const EstimatorInfo& e = estimatorInfo(render.estimator);
    if (!e.resampling) return e.sampler;
    switch (render.source) {
        case LightSource::uniform: return LightSamplerKind::none;
        case LightSource::tree: return LightSamplerKind::tree;
        case LightSource::power:
        case LightSource::tiles:
        case LightSource::regir: return LightSamplerKind::power;
    }
    return LightSamplerKind::none;
}

}  // namespace accretion
