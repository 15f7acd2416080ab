#pragma once
#include <nlohmann/json.hpp>

#include "accretion/io/provenance.h"
#include "accretion/render/frame_renderer.h"

namespace accretion {

/// JSON of one frame's counts and pass times.
nlohmann::json frameStatsJson(const FrameStats& stats);

/// A pass's reuse offers: offered, accepted, m_capped and each outcome's count (kReuseOutcomeNames).
nlohmann::json reuseCountsJson(const ReuseCounts& counts);
/// Pixel windows (crops) as [[x0, x1, y0, y1], ...].
nlohmann::json windowsJson(const std::vector<PixelWindow>& windows);

}  // namespace accretion
