#include "accretion/core/parse.h"

#include <charconv>
#include <cmath>

namespace accretion {

std::optional<std::uint64_t> parseUnsigned(std::string_view text, std::uint64_t max) {
    std::uint64_t v = 0;
    if (text.empty() || text.front() < '0' || text.front() > '9') return std::nullopt;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || v > max) return std::nullopt;
    return v;
}

std::optional<double> parseNumber(std::string_view text) {
    double v = 0.0;
    if (text.empty() || text.front() == '+') return std::nullopt;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

std::vector<std::string> splitList(std::string_view text, char sep) {
    std::vector<std::string> out;
    for (std::size_t start = 0;;) {
        const auto k = text.find(sep, start);
        out.emplace_back(text.substr(start, k == std::string_view::npos ? std::string_view::npos : k - start));
        if (k == std::string_view::npos) return out;
        start = k + 1;
    }
}

}  // namespace accretion
