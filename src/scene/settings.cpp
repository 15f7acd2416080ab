#include "accretion/scene/settings.h"

#include <fmt/format.h>

namespace accretion {

std::string expandPattern(std::string_view pattern, std::string_view scene, std::uint32_t frame) {
    std::string out;
    out.reserve(pattern.size() + 8);
    for (std::size_t i = 0; i < pattern.size();) {
        if (pattern.substr(i, 7) == "{frame}") {
            out += fmt::format("{:04d}", frame);
            i += 7;
        } else if (pattern.substr(i, 7) == "{scene}") {
            out += scene;
            i += 7;
        } else {
            out += pattern[i++];
        }
    }
    return out;
}

}  // namespace accretion
