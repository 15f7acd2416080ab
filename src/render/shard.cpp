#include "accretion/render/shard.h"

#include <algorithm>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/parse.h"

namespace accretion {

std::string Shard::name() const { return fmt::format("shard{}of{}", index, count); }

Shard parseShard(const std::string& text, const char* option) {
    const auto slash = text.find('/');
    auto number = [&](const std::string& s, std::uint32_t& v) {
        const std::optional<std::uint64_t> n = parseUnsigned(s, 999999999);
        if (n) v = static_cast<std::uint32_t>(*n);
        return n.has_value();
    };
    Shard shard;
    if (slash == std::string::npos || !number(text.substr(0, slash), shard.index) ||
        !number(text.substr(slash + 1), shard.count) || shard.count == 0 || shard.index >= shard.count)
        throw InputError(fmt::format("command line {} {}: expected i/n with 0 <= i < n (e.g. 0/4)", option, text));
    return shard;
}

}  // namespace accretion
