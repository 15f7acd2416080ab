#include "accretion/lighting/light_sampler.h"

#include <vector>

#include "accretion/core/math.h"

namespace accretion {

AliasTable buildPowerTable(const Particles& particles) {
    std::vector<float> w(particles.size());
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = luminance(particles.emission[i]);
    return AliasTable(w);
}

}  // namespace accretion
