#pragma once
// The per-pixel light loops of the Monte Carlo estimators (docs/MODEL.md
// section 4), written once for the CPU (src/render/estimators.cpp) and the
// OptiX twin (src/twin/programs.cu) over a bridge B:
//
//   static constexpr bool traced               render --pixel's records (the CPU's traced pixel)
//   bool lightTerm(sp, i, t)                   f I G of light i at sp (false: zero, or i = sp's own particle)
//   void countLightTerm()
//   bool seen(sp, i, t)                        V: one shadow ray, counted (visibility off: 1, no ray)
//   traced only: void traceLight(); void traceTerm(i, t, v); void traceSample(x, term, t, v)
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/shading.h"

namespace accretion {

/// exact (and split's near field): the sum of f I G V over `lights`, every
/// light but the receiver's own particle, in double; one shadow ray per
/// non-zero term.
template <class B, class Lights>
ACC_HD_BODY DVec3 sumLightTerms(B& b, const ShadingPoint& sp, const Lights& lights) {
    DVec3 sum(0.0);
    for (const std::uint32_t i : lights) {
        if (i == sp.self) continue;
        if constexpr (B::traced) b.traceLight();
        LightTerm t;
        b.countLightTerm();
        if (!b.lightTerm(sp, i, t)) continue;
        const bool v = b.seen(sp, i, t);
        if (v) sum += DVec3(t.value);
        if constexpr (B::traced) b.traceTerm(i, t, v);
    }
    return sum;
}

/// uniform / power / tree: the one-sample estimates f I G V / p(i) of drawn
/// lights xs[0, count) into the sums acc (a zero sample when no light or the
/// receiver's own); split: each sample is the near field's exact sum `near`
/// plus the far light's f I G V / p_far(i).
template <class B, class Sums>
ACC_HD_BODY void shadeLightSamples(B& b, const ShadingPoint& sp, const LightSample* xs, std::uint32_t count, const DVec3& near,
                              Sums& acc) {
    const bool hasNear = near != DVec3(0.0);
    for (std::uint32_t k = 0; k < count; ++k) {
        const LightSample& x = xs[k];
        LightTerm t;
        b.countLightTerm();
        const bool term = b.lightTerm(sp, x.i, t);
        const bool v = term && b.seen(sp, x.i, t);
        if (v) acc.add(near + DVec3(t.value) / double(x.pdf));
        else if (hasNear) acc.add(near);
        else acc.addZero();
        if constexpr (B::traced) b.traceSample(x, term, t, v);
    }
}

/// The lights 0 .. count - 1 as a range the device can iterate.
struct LightRange {
    std::uint32_t count;
    struct Iterator {
        std::uint32_t i;
        ACC_HD std::uint32_t operator*() const { return i; }
        ACC_HD Iterator& operator++() { return ++i, *this; }
        ACC_HD bool operator!=(const Iterator& o) const { return i != o.i; }
    };
    ACC_HD Iterator begin() const { return {0}; }
    ACC_HD Iterator end() const { return {count}; }
};

}  // namespace accretion
