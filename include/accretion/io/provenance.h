#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "accretion/scene/settings.h"

namespace accretion {

/// Metadata stored in every frame output (string attributes `accretion:<key>`
/// of an EXR, the metadata of a .gpuframe).
using OutputMetadata = std::map<std::string, std::string>;

/// What made a frame, in the keys every frame output carries, whichever
/// renderer wrote it: version, scene, frame, estimator, samples, seed,
/// shard, render_time_s and the settings as TOML. A renderer adds its own
/// keys to it (the preview's tone; the twin's device and shadow-ray mode).
OutputMetadata frameMetadata(const Settings& settings, const std::string& settingsToml, std::uint32_t frame,
                             std::uint64_t seed, std::string_view shard, double seconds);

/// The head of a run's stats JSON, the same for the CPU renderer and the
/// twin: version, scene, estimator, seed, samples, the settings as TOML and
/// an empty "frames" array for the frames' records.
nlohmann::json statsHeader(const Settings& settings, const std::string& settingsToml);

/// Write a JSON document atomically, pretty-printed.
void writeJson(const std::filesystem::path& file, const nlohmann::json& doc);

}  // namespace accretion
