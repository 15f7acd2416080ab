#include "accretion/analysis/view_check.h"

#include <algorithm>
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

ViewCheck checkView(const std::map<std::string, std::string>& x, const std::map<std::string, std::string>& r,
                    ViewKeys keys) {
    ViewCheck out;
    auto check = [&](const char* key, const char* what) {
        const auto i = x.find(key), j = r.find(key);
        if (i == x.end() || j == r.end()) out.unchecked.emplace_back(what);
        else if (i->second != j->second)
            out.differences.push_back(
                fmt::format("{}: {} here, {} in the reference", what, i->second.substr(0, 80), j->second.substr(0, 80)));
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
    const auto sx = sceneLines(i->second), sr = sceneLines(j->second);
    for (std::size_t k = 0; k < std::max(sx.size(), sr.size()); ++k) {
        const std::string lx = k < sx.size() ? sx[k] : "(none)", lr = k < sr.size() ? sr[k] : "(none)";
        if (lx != lr) {
            out.differences.push_back(fmt::format("scene settings: `{}` here, `{}` in the reference", lx, lr));
            break;
        }
    }
    return out;
}

void requireSceneView(const std::map<std::string, std::string>& attributes, const std::string& file, const Settings& scene,
                      std::uint32_t frame, bool strict) {
    const std::map<std::string, std::string> render = {{"accretion:frame", std::to_string(frame)},
                                                       {"accretion:settings", settingsToToml(scene)}};
    reportViewCheck(checkView(render, attributes, ViewKeys::frameAndSettings),
                    fmt::format("frame {} of {}", frame, scene.scenePath), file, strict, true);
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
