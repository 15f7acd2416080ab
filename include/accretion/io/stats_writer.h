#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "accretion/render/frame_renderer.h"

namespace accretion {

/// JSON of one frame's counts and pass times.
nlohmann::json frameStatsJson(const FrameStats& stats);

/// Write a JSON document atomically, pretty-printed.
void writeJson(const std::filesystem::path& file, const nlohmann::json& doc);

}  // namespace accretion
