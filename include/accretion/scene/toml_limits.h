#pragma once
#include <string_view>

namespace accretion {

/// The deepest nesting a scene or jobs file may use: dotted keys and table
/// headers (`[a.b.c]`), arrays and inline tables, counted together.
inline constexpr int kMaxTomlNesting = 64;

/// Refuse a TOML document nested deeper than kMaxTomlNesting before it is
/// parsed: the parser recurses per level, so a 50,000-level header would
/// overflow the stack. A lexical scan (strings and comments skipped), linear
/// in the text; throws InputError naming `source` and the line.
void checkTomlNesting(std::string_view text, std::string_view source);

}  // namespace accretion
