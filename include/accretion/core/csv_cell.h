#pragma once
// One CSV cell as RFC 4180 writes it, for every CSV accretion writes (the
// report tables, the twin's timings): a label such as "tree, M=8" stays one
// cell, and calibrate's reader (cost_model.cpp, splitCsv) reads it back.
#include <string>
#include <string_view>

namespace accretion {

/// In double quotes, with "" for a quote, when the text holds a comma, a
/// quote or a line break; otherwise as it is.
inline std::string csvCell(std::string_view text) {
    if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

}  // namespace accretion
