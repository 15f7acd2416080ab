// The view check's refusals name the file judged, what it is to the command
// (the reference or a GPU frame) and the setting that differs, by key.
#include <catch2/catch.hpp>

#include "accretion/analysis/view_check.h"
#include "accretion/core/error.h"
#include "accretion/scene/scene_parser.h"

using namespace accretion;
using Catch::Matchers::Contains;
using Catch::Matchers::Equals;

namespace {

Settings sceneNamed(const char* path, std::uint32_t count) {
    Settings s;
    s.scenePath = path;
    s.particles.count = count;
    return s;
}

/// What a render of `s`'s frame `frame` records (the EXR attributes, or a GPU frame's metadata).
std::map<std::string, std::string> recorded(const Settings& s, std::uint32_t frame) {
    return {{"accretion:frame", std::to_string(frame)}, {"accretion:settings", settingsToToml(s)}};
}

std::string refusal(const std::map<std::string, std::string>& attributes, const char* file, FileRole role, const Settings& s,
                    std::uint32_t frame) {
    try {
        requireSceneView(attributes, file, role, s, frame, false);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

}  // namespace

TEST_CASE("a view-check refusal names the file, its role and the setting", "[analysis][view]") {
    const Settings hit = sceneNamed("hit.toml", 100000), other = sceneNamed("other.toml", 999);
    CHECK_THAT(refusal(recorded(other, 0), "gpu.0000.gpuframe", FileRole::gpuFrame, hit, 0),
               Equals("gpu.0000.gpuframe (the GPU frame): not a render of frame 0 of hit.toml: scene settings: "
                      "particles.count = 100000 in hit.toml, 999 in gpu.0000.gpuframe"));
    CHECK_THAT(refusal(recorded(hit, 3), "ref.exr", FileRole::reference, hit, 4),
               Equals("ref.exr (the reference): not a render of frame 4 of hit.toml: frame: 4 in hit.toml, 3 in ref.exr"));
    // A key one side sets and the other leaves out is named, not the next line over.
    Settings withFile = hit;
    withFile.particles.file = "dump.bin";
    CHECK_THAT(refusal(recorded(withFile, 0), "ref.exr", FileRole::reference, hit, 0),
               Contains("particles.file = \"\" in hit.toml, \"dump.bin\" in ref.exr"));
    CHECK(refusal(recorded(hit, 2), "ref.exr", FileRole::reference, hit, 2) == "accepted");
}
