#pragma once
#include <nlohmann/json.hpp>

#include "accretion/io/provenance.h"
#include "accretion/render/frame_renderer.h"

namespace accretion {

/// JSON of one frame's counts and pass times.
nlohmann::json frameStatsJson(const FrameStats& stats);

}  // namespace accretion
