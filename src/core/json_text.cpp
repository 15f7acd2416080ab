#include "accretion/core/json_text.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"

namespace accretion {

namespace {

/// Line and column (1-based) of the byte at `offset` of `text`.
std::string position(std::string_view text, std::size_t offset) {
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') ++line, column = 1;
        else ++column;
    }
    return fmt::format("{}:{}", line, column);
}

/// The offset of the first number token outside strings that overflows a
/// double, or npos. (nlohmann::json stores it as infinity without a word.)
std::size_t firstOverflow(std::string_view text) {
    bool inString = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
            std::size_t end = i + 1;
            while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) ||
                                         std::string_view(".eE+-").find(text[end]) != std::string_view::npos))
                ++end;
            const std::string token(text.substr(i, end - i));
            if (!std::isfinite(std::strtod(token.c_str(), nullptr))) return i;
            i = end - 1;
        }
    }
    return std::string_view::npos;
}

}  // namespace

nlohmann::json parseJsonText(std::string_view text, const std::string& name, std::string_view what) {
    const std::string_view body = withoutBom(text);
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(body.begin(), body.end());
    } catch (const nlohmann::json::parse_error& e) {
        // e.byte is the 1-based offset of the character that failed; the
        // message after its "parse error at line L, column C: " prefix says why.
        std::string why = e.what();
        if (const auto colon = why.find(": "); colon != std::string::npos) why = why.substr(colon + 2);
        const std::size_t at = e.byte > 0 ? e.byte - 1 : 0;
        throw InputError(fmt::format("{}:{}: not valid JSON (a {}): {}", name, position(body, at), what, why));
    } catch (const nlohmann::json::exception& e) {  // out_of_range 406: a number that overflows
        const std::size_t at = firstOverflow(body);
        if (at == std::string_view::npos) throw InputError(fmt::format("{}: not valid JSON (a {}): {}", name, what, e.what()));
        throw InputError(fmt::format("{}:{}: a number beyond the range of a double (a {})", name, position(body, at), what));
    }
    if (const std::size_t at = firstOverflow(body); at != std::string_view::npos)
        throw InputError(fmt::format("{}:{}: a number beyond the range of a double (a {})", name, position(body, at), what));
    return j;
}

}  // namespace accretion
