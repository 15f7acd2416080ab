#include "accretion/analysis/view_check.h"

#include <algorithm>
#include <optional>
#include <utility>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "accretion/core/error.h"
#include "accretion/scene/scene_parser.h"

namespace accretion {

std::vector<std::string> sceneLines(const std::string& toml) {
    std::vector<std::string> out;
    std::istringstream in(toml);
    bool keep = false;
    for (std::string line; std::getline(in, line);) {
        if (!line.empty() && line[0] == '[')
            keep = line == "[particles]" || line == "[camera]" || line == "[geometry]" || line == "[shading]";
        if (keep) out.push_back(line);
    }
    return out;
}

namespace {

/// The scene-defining settings as "section.key" -> value, in file order.
std::vector<std::pair<std::string, std::string>> sceneKeys(const std::string& toml) {
    std::vector<std::pair<std::string, std::string>> out;
    std::string section;
    for (const std::string& line : sceneLines(toml)) {
        if (line.empty()) continue;
        if (line[0] == '[') {
            section = line.substr(1, line.find(']') - 1);
            continue;
        }
        const auto eq = line.find(" = ");
        if (eq == std::string::npos) out.emplace_back(section + "." + line, "");
        else out.emplace_back(section + "." + line.substr(0, eq), line.substr(eq + 3));
    }
    return out;
}

/// The first scene-defining setting the two sides give differently, by key.
std::optional<std::string> settingsDifference(const std::string& x, const std::string& r, const ViewSides& sides) {
    const auto kx = sceneKeys(x), kr = sceneKeys(r);
    const std::map<std::string, std::string> mx(kx.begin(), kx.end()), mr(kr.begin(), kr.end());
    auto value = [](const std::map<std::string, std::string>& m, const std::string& key) {
        const auto i = m.find(key);
        return i == m.end() ? std::string("(not set)") : i->second.substr(0, 80);
    };
    for (const auto* keys : {&kx, &kr})
        for (const auto& [key, v] : *keys)
            if (value(mx, key) != value(mr, key))
                return fmt::format("{} = {} {}, {} {}", key, value(mx, key), sides.image, value(mr, key), sides.reference);
    return std::nullopt;
}

}  // namespace

ViewCheck checkView(const std::map<std::string, std::string>& x, const std::map<std::string, std::string>& r,
                    ViewKeys keys, const ViewSides& sides) {
    ViewCheck out;
    auto check = [&](const char* key, const char* what) {
        const auto i = x.find(key), j = r.find(key);
        if (i == x.end() || j == r.end()) out.unchecked.emplace_back(what);
        else if (i->second != j->second)
            out.differences.push_back(fmt::format("{}: {} {}, {} {}", what, i->second.substr(0, 80), sides.image,
                                                  j->second.substr(0, 80), sides.reference));
    };
    check("accretion:frame", "frame");
    if (keys == ViewKeys::all) {
        check("accretion:scene", "scene");
        check("worldToCamera", "camera (worldToCamera)");
        check("worldToNDC", "projection (worldToNDC)");
        check("accretion:jitter", "jitter");
    }
    const auto i = x.find("accretion:settings"), j = r.find("accretion:settings");
    if (i == x.end() || j == r.end()) {
        out.unchecked.emplace_back("scene settings");
        return out;
    }
    if (auto d = settingsDifference(i->second, j->second, sides)) out.differences.push_back("scene settings: " + *d);
    return out;
}

void requireSceneView(const std::map<std::string, std::string>& attributes, const std::string& file, FileRole role,
                      const Settings& scene, std::uint32_t frame, bool strict) {
    const std::map<std::string, std::string> render = {{"accretion:frame", std::to_string(frame)},
                                                       {"accretion:settings", settingsToToml(scene)}};
    const std::string sceneName = scene.scenePath.empty() ? std::string("the scene") : scene.scenePath;
    const ViewSides sides{fmt::format("in {}", sceneName), fmt::format("in {}", file)};
    const ViewCheck check = checkView(render, attributes, ViewKeys::frameAndSettings, sides);
    const char* what = role == FileRole::reference ? "the reference" : "the GPU frame";
    for (const std::string& d : check.differences)
        throw InputError(fmt::format("{} ({}): not a render of frame {} of {}: {}", file, what, frame, sceneName, d));
    reportViewCheck(check, fmt::format("{} ({})", file, what), sceneName, strict);
}

void reportViewCheck(const ViewCheck& check, const std::string& image, const std::string& reference, bool strict,
                     bool differencesFatal) {
    for (const std::string& d : check.differences) {
        if (strict || differencesFatal) throw InputError(fmt::format("{}: not the reference's view: {}{}", image, d, strict ? " (--strict)" : ""));
        fmt::print(stderr, "accretion: warning: {}: {}\n", image, d);
    }
    if (check.unchecked.empty()) return;
    const std::string what = fmt::format("{} not checked: {} and {} do not both record {}", fmt::join(check.unchecked, ", "),
                                         image, reference, check.unchecked.size() == 1 ? "it" : "them");
    if (strict) throw InputError(fmt::format("{}: {} (--strict)", image, what));
    fmt::print(stderr, "accretion: warning: {}\n", what);
}

}  // namespace accretion
