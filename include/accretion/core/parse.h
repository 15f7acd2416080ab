#pragma once
// The one parser of numbers and lists in command-line and data text (scene
// files go through toml++). Whole-string, locale-independent (from_chars):
// no sign on unsigned values, no whitespace, no trailing characters.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace accretion {

/// Digits only, at most `max`; nothing on anything else (sign, overflow, empty).
std::optional<std::uint64_t> parseUnsigned(std::string_view text, std::uint64_t max = UINT64_MAX);

/// A finite number written in full ("0.5", "1e-3"); nothing otherwise.
std::optional<double> parseNumber(std::string_view text);

/// The pieces between separators ("a,,b" -> a, "", b; "" -> one empty piece).
std::vector<std::string> splitList(std::string_view text, char sep);

}  // namespace accretion
