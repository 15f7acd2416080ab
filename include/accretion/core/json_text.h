#pragma once
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace accretion {

/// A JSON document an input file holds, parsed strictly: a UTF-8 byte-order
/// mark is skipped; a syntax error (a trailing comma, a missing quote) or a
/// number no double holds (1e400) is InputError "NAME:LINE:COLUMN: ..."
/// naming `what` (e.g. "camera file").
nlohmann::json parseJsonText(std::string_view text, const std::string& name, std::string_view what);

}  // namespace accretion
