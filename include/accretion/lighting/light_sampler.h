#pragma once
#include <cstdint>

#include "accretion/core/rng.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/particles/particles.h"

namespace accretion {

/// The light samplers, each with `sample` beside `pdf`:
/// - uniform: sampleSource<false>, sourcePdf<false> (1 / N);
/// - power: sampleSource<true>, sourcePdf<true> (an alias table over luminance(I_i));
/// - tree: LightTree::sample, LightTree::pdf (receiver-dependent, light_tree.h).
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

}  // namespace accretion
