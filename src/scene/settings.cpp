#include "accretion/scene/settings.h"

#include <algorithm>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::string expandPattern(std::string_view pattern, std::string_view scene, std::uint32_t frame) {
    std::string out;
    out.reserve(pattern.size() + 8);
    for (std::size_t i = 0; i < pattern.size();) {
        if (pattern.substr(i, 7) == "{frame}") {
            out += fmt::format("{:04d}", frame);
            i += 7;
        } else if (pattern.substr(i, 7) == "{scene}") {
            if (scene.empty())
                throw InputError(fmt::format("{}: {{scene}} stands for nothing here (no scene names this file); only "
                                             "{{frame}} is expanded", pattern));
            out += scene;
            i += 7;
        } else {
            out += pattern[i++];
        }
    }
    return out;
}

std::optional<SerKeySpec> parseSerKey(std::string_view text, std::string& bad) {
    SerKeySpec key;
    key.components.clear();
    for (std::size_t begin = 0; begin <= text.size();) {
        const std::size_t end = std::min(text.find(',', begin), text.size());
        const std::string_view c = text.substr(begin, end - begin);
        SerComponent component;
        if (!parseEnum(c, component)) {
            bad = std::string(c);
            return std::nullopt;
        }
        key.components.push_back(component);
        begin = end + 1;
    }
    return key;
}

std::string formatSerKey(const SerKeySpec& key) {
    std::string s;
    for (SerComponent c : key.components) s += (s.empty() ? "" : ",") + std::string(enumName(c));
    return s;
}

}  // namespace accretion
