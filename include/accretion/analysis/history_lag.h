#pragma once
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// The lag of a history kept per particle (particle_split.history,
/// restir.texel_history): what an exponential average of a particle's light
/// over its frames errs when every frame is exact, so that nothing but the
/// light's change from frame to frame is left. Fed a reference's frames in
/// order (each pixel's light and the particle it sees), it keeps each
/// visible particle's mean light over its pixels and averages it as
/// particle_split averages a texel: this frame's weighs w = 1 - h (a
/// particle's first frame in view: all of it), or with history_start mean
/// w = max(1 - h, 1 / n) after n frames in view; a particle out of view
/// loses its history. An estimator's history is unbiased frame by frame
/// only where this is 0: the rest of its bias is its own.
struct LagRule {
    double history = 0.95;  ///< h, in [0, 1)
    HistoryStart start = HistoryStart::mean;
};

/// The last frame's pixels with their particle's history against its light now.
struct LagOutcome {
    LagRule rule;
    std::size_t particles = 0;  ///< those the last frame's measured pixels see
    std::size_t fresh = 0;      ///< of them, new to the view in that frame (no history)
    double now = 0.0;           ///< the last frame's light, summed over its pixels (mean of RGB): each pixel its particle's mean
    double history = 0.0;       ///< the same with each pixel its particle's history
    double whole = 0.0;         ///< the same of the whole light (addFrame's `whole`; `now` without it)
    double relMSE = 0.0;        ///< the histories against the means, over the frame's pixels, relative to the whole light (kRelMseEpsilon)
    /// The energy the lag adds to the whole light (negative: the history is darker), in percent.
    double energyPct() const { return whole > 0.0 ? 100.0 * (history - now) / whole : 0.0; }
};

/// The last frame's particles' light in an earlier frame: sum over the last
/// frame's pixels whose particle was in view then of its mean then, over
/// the same pixels' sum now (1: as bright as now).
struct LagTrendPoint {
    std::uint32_t frame = 0;
    double ratio = 0.0;
    double tracked = 0.0;  ///< the fraction of the last frame's lit pixels whose particle was in view then
};

class HistoryLag {
public:
    explicit HistoryLag(std::vector<LagRule> rules);

    /// The next frame: per pixel its light and its particle (kNoParticle: none);
    /// every frame the same size. `whole` (or empty: `light`) is the light
    /// the error is measured against, where `light` is part of it (the far
    /// light, which particle_split.history_of far averages).
    void addFrame(std::uint32_t frame, const std::vector<Vec3>& light, const std::vector<std::uint32_t>& particle,
                  const std::vector<Vec3>& whole = {});

    /// Each rule's outcome at the last frame added, over its pixels p with
    /// measured[p] (empty: all of them; e.g. crops of the frame).
    std::vector<LagOutcome> outcomes(const std::vector<bool>& measured = {}) const;
    /// The last frame's particles in each frame added, oldest first (over the same pixels).
    std::vector<LagTrendPoint> trend(const std::vector<bool>& measured = {}) const;

private:
    struct Kept {
        DVec3 value{0.0};
        std::uint32_t age = 0;  ///< frames in view, this one counted
    };
    std::vector<LagRule> rules_;
    std::vector<std::unordered_map<std::uint32_t, Kept>> kept_;  ///< per rule, the particles in the last frame's view
    std::unordered_map<std::uint32_t, DVec3> lastMean_;          ///< the last frame's particles' means
    std::unordered_map<std::uint32_t, DVec3> lastWhole_;         ///< and of their whole light
    std::vector<std::uint32_t> lastParticle_;
    /// Every frame's particles' mean light (mean of RGB), by id, for trend().
    std::vector<std::pair<std::uint32_t, std::unordered_map<std::uint32_t, float>>> frames_;
};

}  // namespace accretion
