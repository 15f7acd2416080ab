#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/pass.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/lighting/reservoir_codec.h"

namespace accretion {

/// render --pixel: what the lighting of one pixel did, recorded by the
/// estimators as they run (the same code as every other pixel's, so the
/// value shown is the value of the full render).
struct PixelTrace {
    std::size_t px = 0;  ///< the pixel traced, y * width + x

    /// exact: a light whose unshadowed term f I G is non-zero, and V.
    struct Term {
        std::uint32_t light;
        Vec3 value;
        bool visible;
    };
    std::vector<Term> terms;
    std::uint64_t lightsSeen = 0;  ///< exact: lights evaluated (the rest of N - 1 had a zero term)

    /// uniform / power / tree: one drawn light and its one-sample estimate.
    struct Sample {
        std::uint32_t light;
        float pdf;
        Vec3 value;     ///< f I G (0 when the light gives nothing here)
        bool visible;
        Vec3 estimate;  ///< f I G V / pdf
    };
    std::vector<Sample> samples;

    /// ris: one reservoir: its candidates, the one kept, its shadow ray.
    struct Candidate {
        std::uint32_t light;
        float pdf, p_hat, w;  ///< source pdf, target, resampling weight p_hat / pdf
    };
    struct RisReservoir {
        std::vector<Candidate> candidates;
        Reservoir reservoir;  ///< finalized
        bool visible = false;
        Vec3 estimate{0.0f};  ///< f I G V W of the kept light
    };
    std::vector<RisReservoir> reservoirs;

    /// restir: the pixel's reservoir after each pass (at its lighting texel).
    struct PassState {
        PassRun pass;
        StoredReservoir reservoir;
    };
    std::vector<PassState> passes;
};

}  // namespace accretion
