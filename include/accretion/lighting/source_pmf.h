#pragma once
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/lighting/alias_table.h"
#include "accretion/lighting/light_sample.h"

namespace accretion {

/// sampleSource<Power> (light_sampler.h) as plain data, for code that holds
/// no AliasTable or LightArrays (the OptiX twin): a uniform light, or one in
/// proportion to luminance(I_i) from the alias table's arrays. Bucket, then
/// coin, from the same stream: with Rng or PortableRng of the same seed it
/// draws the CPU's lights (tests/lighting/light_sampler_test.cpp).
struct SourcePmf {
    bool power = false;
    AliasTableView table;        ///< power: buildPowerTable's arrays
    std::uint32_t count = 0;     ///< lights
    float uniformPdf = 0.0f;     ///< 1 / count, rounded as LightArrays does

    template <class R>
    ACC_HD LightSample sample(R& rng) const {
        const std::uint32_t bucket = rng.uniformInt(count);
        if (!power) return {bucket, uniformPdf};
        const std::uint32_t i = table.sample(bucket, rng.uniform());
        return {i, table.pmf[i]};
    }
};

}  // namespace accretion
