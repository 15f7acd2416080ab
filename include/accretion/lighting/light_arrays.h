#pragma once
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/particles/particles.h"
#include "accretion/lighting/shading.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// What a light sample reads, in one half cache line (a random light costs
/// one miss, not four).
struct alignas(32) PackedLight {
    Vec3 position;
    float dmin2;     ///< max(r_i, dmin)^2
    Vec3 emission;
    float radius;
};

/// The lights of a frame as the hot loops read them (views of the particle
/// arrays, and the packed records the samplers read).
struct LightArrays {
    const Vec3* position = nullptr;
    const Vec3* emission = nullptr;
    const float* radius = nullptr;
    std::vector<PackedLight> packed;
    std::uint32_t count = 0;
    IntBound countBound;       ///< [0, count) without divisions
    float uniformPdf = 0.0f;   ///< 1 / count

    LightArrays() = default;
    LightArrays(const Particles& particles, const ShadingSettings& shading) {
        position = particles.position.data();
        emission = particles.emission.data();
        radius = particles.radius.data();
        count = static_cast<std::uint32_t>(particles.size());
        uniformPdf = count ? 1.0f / float(count) : 0.0f;
        if (count) countBound = IntBound(count);
        packed.resize(count);
        const float dmin = static_cast<float>(shading.dmin);
        for (std::uint32_t i = 0; i < count; ++i) {
            const float d = std::max(particles.radius[i], dmin);
            packed[i] = {position[i], d * d, emission[i], radius[i]};
        }
    }

    /// Unshadowed term of light i at the receiver (0 for its own particle).
    template <ShadingModel M>
    [[gnu::always_inline]] bool term(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        if (i == sp.self || i >= count) return false;
        const PackedLight& l = packed[i];
        return evalLight<M>(sp, l.position, l.emission, l.dmin2, t);
    }
    /// RIS target p_hat = luminance(f I G), no visibility.
    template <ShadingModel M>
    [[gnu::always_inline]] float targetPdf(const ShadingPoint& sp, std::uint32_t i) const {
        LightTerm t;
        return term<M>(sp, i, t) ? luminance(t.value) : 0.0f;
    }
};

}  // namespace accretion
