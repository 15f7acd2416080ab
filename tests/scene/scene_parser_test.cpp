#include <catch2/catch.hpp>

#include <fstream>

#include "accretion/core/error.h"
#include "accretion/scene/scene_parser.h"
#include "support/test_scenes.h"

using namespace accretion;
using Catch::Matchers::Contains;

namespace {
std::string errorOf(std::string_view text, const std::vector<std::string>& overrides = {}) {
    try {
        parseScene(text, "bad.toml", overrides);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}
}  // namespace

TEST_CASE("defaults when the scene is empty", "[scene]") {
    const Settings s = parseScene("", "empty.toml");
    REQUIRE(s.particles.count == ParticleSettings{}.count);
    REQUIRE(s.render.estimator == EstimatorKind::exact);
    REQUIRE(s.camera.width == 640);
}

TEST_CASE("typed values are read", "[scene]") {
    const Settings s = parseScene(R"(
[particles]
count = 123
inner_radius = 2
[camera]
position = [1, 2, 3.5]
[geometry]
orientation = "velocity"
alpha = "disc"
build = "refit"
[shading]
model = "isotropic"
dmin = 0.5
[render]
estimator = "power"
samples = 7
seed = 99
frames = 2
output = "o/{frame}.exr"
)", "ok.toml");
    REQUIRE(s.particles.count == 123);
    REQUIRE(s.particles.inner_radius == 2.0);
    REQUIRE(s.camera.position == Vec3(1.0f, 2.0f, 3.5f));
    REQUIRE(s.geometry.orientation == Orientation::velocity);
    REQUIRE(s.geometry.alpha == AlphaMode::disc);
    REQUIRE(s.geometry.build == BuildPolicy::refit);
    REQUIRE(s.shading.model == ShadingModel::isotropic);
    REQUIRE(s.render.estimator == EstimatorKind::power);
    REQUIRE(s.render.samples == 7);
    REQUIRE(s.render.seed == 99);
}

TEST_CASE("errors name file, line and key", "[scene][errors]") {
    CHECK_THAT(errorOf("[render]\n\nsamples = \"many\"\n"), Contains("bad.toml:3") && Contains("render.samples") && Contains("integer"));
    CHECK_THAT(errorOf("[render]\nsampels = 4\n"), Contains("bad.toml:2") && Contains("render.sampels") && Contains("unknown setting"));
    CHECK_THAT(errorOf("[rendr]\nsamples = 4\n"), Contains("bad.toml:1") && Contains("rendr"));
    CHECK_THAT(errorOf("[camera]\nwidth = 0\n"), Contains("bad.toml:2") && Contains("camera.width") && Contains(">= 1"));
    CHECK_THAT(errorOf("[camera]\nwidth = 100000\n"), Contains("camera.width") && Contains("<= 16384"));
    CHECK_THAT(errorOf("[particles]\nradius = -1.0\n"), Contains("bad.toml:2") && Contains("particles.radius") && Contains("> 0"));
    CHECK_THAT(errorOf("[particles]\nradius = nan\n"), Contains("particles.radius") && Contains("finite"));
    CHECK_THAT(errorOf("[particles]\ncount = -5\n"), Contains("particles.count") && Contains(">= 0"));
    CHECK_THAT(errorOf("[geometry]\norientation = \"sideways\"\n"),
               Contains("bad.toml:2") && Contains("geometry.orientation") && Contains("view_plane | view_point | velocity"));
    CHECK_THAT(errorOf("[camera]\nposition = [1, 2]\n"), Contains("camera.position") && Contains("3 numbers"));
    CHECK_THAT(errorOf("[particles]\ninner_radius = 5.0\nouter_radius = 4.0\n"),
               Contains("bad.toml:3") && Contains("particles.outer_radius"));
    CHECK_THAT(errorOf("[render]\nframes = 3\noutput = \"x.exr\"\n"), Contains("bad.toml:3") && Contains("{frame}"));
    CHECK_THAT(errorOf("render = 3\n"), Contains("bad.toml:1") && Contains("must be a table"));
    CHECK_THAT(errorOf("[render]\nsamples = 4\nsamples = 5\n"), Contains("bad.toml:3"));  // duplicate key
    CHECK_THAT(errorOf("[render\n"), Contains("bad.toml:1"));  // syntax
}

TEST_CASE("command-line overrides use the same validation and name the flag", "[scene][overrides]") {
    const Settings s = parseScene("[render]\nsamples = 4\n", "ok.toml",
                                  {"render.samples=64", "render.estimator=power", "camera.position=[0, 1, 2]",
                                   "render.output=out/x_{frame}.exr", "render.frames=2"});
    REQUIRE(s.render.samples == 64);
    REQUIRE(s.render.estimator == EstimatorKind::power);
    REQUIRE(s.camera.position == Vec3(0.0f, 1.0f, 2.0f));
    REQUIRE(s.render.output == "out/x_{frame}.exr");
    CHECK_THAT(errorOf("", {"render.samples=zero"}), Contains("-D render.samples=zero") && Contains("integer"));
    CHECK_THAT(errorOf("", {"render.bogus=1"}), Contains("-D render.bogus") && Contains("unknown setting"));
    CHECK_THAT(errorOf("", {"samples=1"}), Contains("section.key"));
    CHECK_THAT(errorOf("", {"camera.fov=400"}), Contains("-D camera.fov=400") && Contains("<= 179"));
}

TEST_CASE("effective settings round-trip through TOML", "[scene]") {
    Settings a = parseScene("[render]\nestimator = \"uniform\"\nsamples = 3\n[camera]\nfov = 33.5\n", "a.toml");
    const std::string text = settingsToToml(a);
    const Settings b = parseScene(text, "b.toml");
    REQUIRE(settingsToToml(b) == text);
    REQUIRE(b.render.estimator == EstimatorKind::uniform);
    REQUIRE(b.camera.fov == 33.5);
}

TEST_CASE("loadScene names a missing file", "[scene][errors]") {
    try {
        loadScene("/nonexistent/scene.toml");
        FAIL("no error");
    } catch (const InputError& e) {
        REQUIRE_THAT(e.what(), Contains("/nonexistent/scene.toml"));
    }
}

TEST_CASE("every committed scene parses", "[scene]") {
    for (const auto& entry : std::filesystem::directory_iterator(std::string(ACCRETION_SOURCE_DIR) + "/scenes"))
        if (entry.path().extension() == ".toml") {
            INFO(entry.path());
            REQUIRE_NOTHROW(loadScene(entry.path()));
        }
}
