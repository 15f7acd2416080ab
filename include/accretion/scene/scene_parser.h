#pragma once
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "accretion/scene/settings.h"

namespace accretion {

/// A setting a typed command-line flag sets (after the file and the -D
/// overrides, before the range and cross-field checks, which then name the flag).
struct FlagSetting {
    std::string key;                      ///< "render.estimator"
    std::string flag;                     ///< "--estimator restir"
    std::function<void(Settings&)> apply;
};

/// Load a TOML scene, apply `-D section.key=value` overrides, then the flags.
/// Throws InputError naming file:line (or the -D or other flag) and the key.
Settings loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {},
                   const std::vector<FlagSetting>& flags = {});

/// Same, from text; `sourceName` is used in error messages.
Settings parseScene(std::string_view text, std::string_view sourceName,
                    const std::vector<std::string>& overrides = {}, const std::vector<FlagSetting>& flags = {});

/// Parse `A:B` (half-open, 0 <= A < B) or `A` (= A:A+1) of a command-line
/// option; InputError names the option.
std::pair<std::uint64_t, std::uint64_t> parseHalfOpen(const std::string& text, const char* option);

/// `--frames A:B` as the settings it sets (render.frame_start, render.frames).
std::vector<FlagSetting> frameFlags(const std::string& frames);

/// The effective settings as a TOML document (every key, defaults included).
std::string settingsToToml(const Settings& settings);

/// One line per setting: `section.key = default  # doc`.
std::string settingsReference();

}  // namespace accretion
