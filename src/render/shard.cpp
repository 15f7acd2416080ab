#include "accretion/render/shard.h"

#include <algorithm>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::string Shard::name() const { return fmt::format("shard{}of{}", index + 1, count); }

Shard parseShard(const std::string& text, const char* option) {
    const auto slash = text.find('/');
    auto number = [&](const std::string& s, std::uint32_t& v) {
        if (s.empty() || s.size() > 9 || !std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; }))
            return false;
        v = static_cast<std::uint32_t>(std::stoul(s));
        return true;
    };
    Shard shard;
    if (slash == std::string::npos || !number(text.substr(0, slash), shard.index) ||
        !number(text.substr(slash + 1), shard.count) || shard.count == 0 || shard.index >= shard.count)
        throw InputError(fmt::format("command line {} {}: expected i/n with 0 <= i < n (e.g. 0/4)", option, text));
    return shard;
}

}  // namespace accretion
