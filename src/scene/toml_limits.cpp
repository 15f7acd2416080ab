#include "accretion/scene/toml_limits.h"

#include <vector>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

namespace {

/// Past the string whose quote is text[i], counting its lines: the index of
/// its last character (of the line, for an unterminated one-line string:
/// the parser reports it).
std::size_t skipString(std::string_view text, std::size_t i, std::size_t& line) {
    const std::size_t n = text.size();
    const char c = text[i];
    const std::string_view triple(c == '"' ? "\"\"\"" : "'''");
    const bool multi = text.substr(i, 3) == triple;
    i += multi ? 3 : 1;
    for (; i < n; ++i) {
        if (text[i] == '\n') {
            ++line;
            if (!multi) break;
        }
        if (c == '"' && text[i] == '\\') {
            ++i;
            if (i < n && text[i] == '\n') ++line;
            continue;
        }
        if (text[i] == c && (!multi || text.substr(i, 3) == triple)) {
            if (multi) i += 2;
            break;
        }
    }
    return i;
}

/// Where the scan is: reading a key (a line's start, or inside an inline
/// table) with `dots` levels so far, a [header], or a value; `open` holds
/// the value's brackets ('[' or '{'), outermost first.
struct NestingScan {
    enum class Mode { key, header, value } mode = Mode::key;
    std::vector<char> open;
    int dots = 0, innerDots = 0;  // the line's key; the current inline table's key

    int depth() const { return dots + innerDots + int(open.size()); }
    void newline() {
        if (open.empty() && mode != Mode::header) {
            mode = Mode::key;
            dots = 0;
        }
    }
    /// One character outside strings and comments; `next` the one after it (or 0).
    void step(char c, char next) {
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
            else if (c == ']' && next != ']') {
                mode = Mode::key;
                dots = 0;
            }
            break;
        case Mode::value:  // a '.' here is a float's point, not a level
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
            }
            break;
        }
    }
};

}  // namespace

void checkTomlNesting(std::string_view text, std::string_view source) {
    std::size_t line = 1;
    NestingScan scan;
    const std::size_t n = text.size();
    for (std::size_t i = 0; i < n; ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
            scan.newline();
        } else if (c == '#') {  // a comment runs to the end of the line
            while (i + 1 < n && text[i + 1] != '\n') ++i;
        } else if (c == '"' || c == '\'') {  // strings: skipped, their lines counted
            i = skipString(text, i, line);
        } else {
            scan.step(c, i + 1 < n ? text[i + 1] : '\0');
            if (scan.depth() > kMaxTomlNesting)
                throw InputError(fmt::format("{}:{}: nested deeper than {} levels (dotted keys, table headers, arrays and "
                                             "inline tables together)", source, line, kMaxTomlNesting));
        }
    }
}

}  // namespace accretion
