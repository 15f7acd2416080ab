#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "accretion/scene/settings.h"

namespace accretion {

/// Load a TOML scene and apply `-D section.key=value` overrides.
/// Throws InputError naming file:line (or the -D flag) and the key.
Settings loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// Same, from text; `sourceName` is used in error messages.
Settings parseScene(std::string_view text, std::string_view sourceName,
                    const std::vector<std::string>& overrides = {});

/// The effective settings as a TOML document (every key, defaults included).
std::string settingsToToml(const Settings& settings);

/// One line per setting: `section.key = default  # doc`.
std::string settingsReference();

}  // namespace accretion
