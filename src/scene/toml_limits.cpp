#include "accretion/scene/toml_limits.h"

#include <vector>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

void checkTomlNesting(std::string_view text, std::string_view source) {
    std::size_t line = 1;
    auto refuse = [&] {
        throw InputError(fmt::format("{}:{}: nested deeper than {} levels (dotted keys, table headers, arrays and inline "
                                     "tables together)", source, line, kMaxTomlNesting));
    };
    // Where the scan is: reading a key (a line's start, or inside an inline
    // table) with `dots` levels so far, a [header], or a value; `open` holds
    // the value's brackets ('[' or '{'), outermost first.
    enum class Mode { key, header, value } mode = Mode::key;
    std::vector<char> open;
    int dots = 0, innerDots = 0;  // the line's key; the current inline table's key
    auto depth = [&] { return dots + innerDots + int(open.size()); };
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n; ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
            if (open.empty() && mode != Mode::header) {
                mode = Mode::key;
                dots = 0;
            }
            continue;
        }
        if (c == '#') {  // a comment runs to the end of the line
            while (i + 1 < n && text[i + 1] != '\n') ++i;
            continue;
        }
        if (c == '"' || c == '\'') {  // strings: skip, counting their lines
            const bool multi = text.substr(i, 3) == std::string_view(c == '"' ? "\"\"\"" : "'''");
            i += multi ? 3 : 1;
            for (; i < n; ++i) {
                if (text[i] == '\n') {
                    ++line;
                    if (!multi) break;  // unterminated: the parser reports it
                }
                if (c == '"' && text[i] == '\\') {
                    ++i;
                    if (i < n && text[i] == '\n') ++line;
                    continue;
                }
                if (text[i] == c && (!multi || text.substr(i, 3) == std::string_view(c == '"' ? "\"\"\"" : "'''"))) {
                    if (multi) i += 2;
                    break;
                }
            }
            continue;
        }
        switch (mode) {
        case Mode::key:
            if (c == '[' && open.empty() && dots == 0) {
                mode = Mode::header;
            } else if (c == '.') {
                ++(open.empty() ? dots : innerDots);
            } else if (c == '=') {
                mode = Mode::value;
            } else if (c == '}' && !open.empty()) {  // an empty inline table
                open.pop_back();
                innerDots = 0;
                mode = Mode::value;
            }
            break;
        case Mode::header:
            if (c == '.') ++dots;
            else if (c == ']' && (i + 1 >= n || text[i + 1] != ']')) {
                mode = Mode::key;
                dots = 0;
            }
            break;
        case Mode::value:
            if (c == '[' || c == '{') {
                open.push_back(c);
                if (c == '{') {
                    mode = Mode::key;
                    innerDots = 0;
                }
            } else if ((c == ']' || c == '}') && !open.empty()) {
                open.pop_back();
                if (c == '}') innerDots = 0;
            } else if (c == ',' && !open.empty() && open.back() == '{') {
                mode = Mode::key;
                innerDots = 0;
            } else if (c == '.') {
                continue;  // a float's point, not a level
            }
            break;
        }
        if (depth() > kMaxTomlNesting) refuse();
    }
}

}  // namespace accretion
