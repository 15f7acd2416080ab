#pragma once
#include <cstdint>
#include <string>

namespace accretion {

/// A part of the work given to one process: shard `index` of `count`.
struct Shard {
    std::uint32_t index = 0;  ///< 0-based
    std::uint32_t count = 1;
    bool whole() const { return count == 1; }
    std::string name() const;  ///< "shard0of4": the index as --shard I/N gives it (0-based)
};

/// Parse "i/n" (0 <= i < n). Throws InputError naming `option`.
Shard parseShard(const std::string& text, const char* option);

}  // namespace accretion
