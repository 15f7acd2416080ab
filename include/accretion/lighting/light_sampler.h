#pragma once
#include <cstdint>

#include "accretion/core/rng.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/estimator_table.h"

namespace accretion {

/// The light samplers, each with `sample` beside `pdf`:
/// - uniform: sampleSource<false>, sourcePdf<false> (1 / N);
/// - power: sampleSource<true>, sourcePdf<true> (an alias table over luminance(I_i));
/// - tree: LightTree::sample, LightTree::pdf (receiver-dependent, light_tree.h);
/// - ris / restir candidates by render.source: CandidateSampler<S>::sample, pmf;
/// - split's far field: LightTree::sampleFar, pdfFar (near_field.cpp);
/// - restir's presampled sources: LightTiles::sample with the power pmf as
///   its marginal pdf (light_tiles.h), RegirGrid::sample whose pdf is 1 / W,
///   W an unbiased estimate of 1 / p_src (regir_grid.h).
/// tests/lighting/light_sampler_test.cpp runs one chi-square harness over all of them.

/// The light selection pmf of the `power` estimator (and of ris / restir with
/// render.source = power): an alias table over luminance(I_i).
AliasTable buildPowerTable(const Particles& particles);

/// One light from a receiver-independent source pmf: uniform, or in
/// proportion to power (alias table). Bucket then coin, in that order.
template <bool Power>
LightSample sampleSource(const LightArrays& L, const AliasTable* table, Rng& rng) {
    if constexpr (Power) {
        const std::uint32_t bucket = rng.uniformInt(L.countBound);
        const std::uint32_t i = table->sample(bucket, rng.uniform());
        return {i, table->pmf(i)};
    } else {
        return {rng.uniformInt(L.countBound), L.uniformPdf};
    }
}

/// Probability that sampleSource<Power> returns light i.
template <bool Power>
float sourcePdf(const LightArrays& L, const AliasTable* table, std::uint32_t i) {
    if constexpr (Power) return table->pmf(i);
    else return L.uniformPdf;
}

/// The light sampler of a render.source that draws at the receiver (as
/// pbrt-v4's LightSampler: `sample` beside `pmf`, one type per source; the
/// presampled sources are LightTiles and RegirGrid): uniform, power (alias
/// table) or the light tree. What ris's and restir's candidates draw from,
/// and what the chi-square harness checks. The tree may draw no light
/// (kNoLightSample, pdf 0) where every light has zero importance: the
/// caller counts it as a zero candidate.
template <LightSource S>
struct CandidateSampler {
    static_assert(!sourceInfo(S).presampled, "a presampled source draws from its tiles or grid");
    const LightArrays& L;
    const AliasTable* table;  ///< power's alias table (kLightSources' sampler column)
    const LightTree* tree;    ///< tree's light tree

    LightSample sample(const ShadingPoint& sp, Rng& rng) const {
        if constexpr (S == LightSource::tree) return tree->sample(sp, rng);
        else return sampleSource<S == LightSource::power>(L, table, rng);
    }
    /// The probability that sample() returns light i at the receiver.
    float pmf(const ShadingPoint& sp, std::uint32_t i) const {
        if constexpr (S == LightSource::tree) return tree->pdf(sp, i);
        else return sourcePdf<S == LightSource::power>(L, table, i);
    }
};

}  // namespace accretion
