// The accretion binary as a user runs it: real processes, real files.
#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>
#include <iterator>
#include <string>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

using namespace accretion;
using namespace accretion::test;

namespace {


/// A small version of the quickstart scene.
std::string smallQuickstart() {
    return kBin + " render " + kScenes + "/quickstart.toml --quiet -D particles.count=800 -D camera.width=80"
                  " -D camera.height=45 -D render.frames=1";
}

/// All channels of an EXR as floats (particle.id converts exactly).
std::vector<float> readPixels(const std::filesystem::path& file) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const auto& spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    return px;
}

bool bitIdentical(const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST_CASE("bit-identical EXR for 1 and 2 threads", "[cli][determinism]") {
    const auto dir = accretion::test::scratchDir("threads");
    // restir: three frames of temporal + spatial reuse (pairwise, packed
    // reservoirs, reduced resolution); tree: adaptive sampling.
    const std::string estimator = GENERATE("exact", "power", "uniform", "ris", "tree", "split", "restir", "particle_restir", "voxel_cache",
                                            "particle_split");
    const bool reuse = estimator == std::string("restir") || estimator == std::string("particle_restir") ||
                       estimator == std::string("voxel_cache") || estimator == std::string("particle_split");
    std::string extra = " --spp 8";
    if (estimator == std::string("tree")) extra += " --target-stderr 5% -D render.max_samples=64";
    // split: k from the pilot (threads work on one cache each); more lights than the near field holds.
    if (estimator == std::string("split")) extra += " -D particles.count=2000";
    if (estimator == std::string("restir"))
        extra = " -D render.frames=3 -D restir.bias_correction=\"pairwise\" -D restir.layout=\"packed\""
                " -D restir.resolution_scale=0.5 -D particles.gm=40";
    // particle_restir: texels 2x2 with 2 layers, world neighbours, the pixels resampling them.
    if (estimator == std::string("particle_restir"))
        extra = " -D render.frames=3 -D restir.texels=2 -D restir.texel_rays=2 -D restir.pixel_shading=\"resample\""
                " -D particles.gm=40";
    // voxel_cache: three frames of the cells' running mean, lights from the tree.
    if (estimator == std::string("voxel_cache"))
        extra = " -D render.frames=3 -D render.source=\"tree\" -D voxel.cells=16 -D particles.gm=40";
    // particle_split: three frames of 2x2 texels averaged by id, near and far lights.
    if (estimator == std::string("particle_split"))
        extra = " -D render.frames=3 -D particle_split.texels=2 -D particle_split.history=0.5 -D particle_split.near=8"
                " -D particle_split.far=4 -D particles.gm=40";
    const std::string last = reuse ? ".0002.exr" : ".exr";
    const std::string pattern = reuse ? ".{frame}.exr" : ".exr";
    std::string out;
    for (int t : {1, 2}) {
        const std::string cmd = smallQuickstart() + " --estimator " + estimator + extra + " --threads " +
                                std::to_string(t) + " -o " + (dir / ("t" + std::to_string(t) + pattern)).string();
        INFO(cmd << "\n" << out);
        REQUIRE(runCommand(cmd, out) == 0);
    }
    const auto a = readPixels(dir / ("t1" + last)), b = readPixels(dir / ("t2" + last));
    REQUIRE(bitIdentical(a, b));
    // Another seed changes a Monte Carlo image.
    if (estimator != std::string("exact")) {
        REQUIRE(runCommand(smallQuickstart() + " --estimator " + estimator + extra + " --seed 5 -o " +
                               (dir / ("s5" + pattern)).string(), out) == 0);
        REQUIRE_FALSE(bitIdentical(a, readPixels(dir / ("s5" + last))));
    }
}

TEST_CASE("render writes EXR, PNG previews, stats and settings", "[cli]") {
    const auto dir = accretion::test::scratchDir("outputs");
    std::string out;
    const std::string cmd = smallQuickstart() + " -D render.frames=2 -o " + (dir / "q.{frame}.exr").string();
    REQUIRE(runCommand(cmd, out) == 0);
    for (const char* f : {"q.0000.exr", "q.0001.exr", "q.0000.png", "q.0000.Lr.png", "q.stats.json", "q.settings.toml"})
        REQUIRE(std::filesystem::exists(dir / f));
    REQUIRE_THAT(out, Contains("q.0001.exr") && Contains("q.stats.json"));
    std::ifstream in(dir / "q.stats.json");
    const auto stats = nlohmann::json::parse(in);
    REQUIRE(stats["frames"].size() == 2);
    const auto& f0 = stats["frames"][0];
    REQUIRE(f0["counts"]["particles"] == 800);
    REQUIRE(f0["counts"]["triangles"] == 1600);
    REQUIRE(f0["rays"]["primary"] == 80 * 45);
    REQUIRE(f0["rays"]["shadow"].get<std::uint64_t>() > 0);
    REQUIRE(f0["bvh"]["embree_bytes"].get<std::int64_t>() > 0);
    for (const char* pass : {"loadParticles", "buildClusters", "traceGBuffer", "estimateLighting", "composeImage", "writeOutputs"})
        REQUIRE(f0["passes"].contains(pass));
    REQUIRE(stats["version"].get<std::string>().size() > 0);
    // The frames differ (Keplerian motion) and the settings file reloads.
    REQUIRE_FALSE(bitIdentical(readPixels(dir / "q.0000.exr"), readPixels(dir / "q.0001.exr")));
    REQUIRE(runCommand(kBin + " render " + (dir / "q.settings.toml").string() + " --quiet -D render.frames=1 -o " +
                           (dir / "again.exr").string(), out) == 0);
}

TEST_CASE("bad input: one clear error, non-zero exit, no output", "[cli][errors]") {
    const auto dir = accretion::test::scratchDir("bad_cli");
    std::string out;
    {
        std::ofstream(dir / "bad.toml") << "[render]\nsamples = 4\n\n[camera]\nfov = \"wide\"\n";
    }
    REQUIRE(runCommand(kBin + " render " + (dir / "bad.toml").string() + " -o " + (dir / "x.exr").string(), out) == 1);
    REQUIRE_THAT(out, Contains("bad.toml:5") && Contains("camera.fov"));
    REQUIRE(runCommand(smallQuickstart() + " -D render.samples=-3 -o " + (dir / "x.exr").string(), out) == 1);
    REQUIRE_THAT(out, Contains("-D render.samples=-3"));
    REQUIRE(runCommand(smallQuickstart() + " --frames 5:2 -o " + (dir / "x.exr").string(), out) == 1);
    REQUIRE_THAT(out, Contains("--frames 5:2"));
    REQUIRE(runCommand(smallQuickstart() + " -D particles.file=" + (dir / "none.bin").string() + " -o " +
                           (dir / "x.exr").string(), out) == 1);
    REQUIRE_THAT(out, Contains("none.bin"));
    REQUIRE(runCommand(kBin + " render " + (dir / "missing.toml").string(), out) == 1);
    REQUIRE_THAT(out, Contains("missing.toml"));
    REQUIRE_FALSE(std::filesystem::exists(dir / "x.exr"));
    REQUIRE(runCommand(kBin + " render", out) != 0);  // missing argument: CLI11's usage error
}

TEST_CASE("particles command: the GPU buffer renders the same image as the generator", "[cli][particles]") {
    const auto dir = accretion::test::scratchDir("particles_cmd");
    std::string out;
    const std::string scene = kScenes + "/quickstart.toml";
    REQUIRE(runCommand(kBin + " particles " + scene + " --frames 0:2 -D particles.count=800 --out " + (dir / "p").string(), out) == 0);
    REQUIRE(std::filesystem::file_size(dir / "p" / "quickstart.0000.bin") == 800 * 32);
    REQUIRE(std::filesystem::exists(dir / "p" / "quickstart.0001.bin"));
    const std::string common = " --quiet --estimator power --spp 4 -D camera.width=80 -D camera.height=45 -D render.frames=1";
    REQUIRE(runCommand(kBin + " render " + scene + common + " -D particles.count=800 -o " + (dir / "gen.exr").string(), out) == 0);
    REQUIRE(runCommand(kBin + " render " + scene + common + " -D particles.file=" + (dir / "p" / "quickstart.{frame}.bin").string() +
                           " -o " + (dir / "file.exr").string(), out) == 0);
    REQUIRE(bitIdentical(readPixels(dir / "gen.exr"), readPixels(dir / "file.exr")));
}

TEST_CASE("accretion plan prints every pass, the skipped ones with their reason", "[cli][plan]") {
    std::string out;
    const std::string scene = std::string(ACCRETION_SOURCE_DIR) + "/scenes/quickstart.toml";
    REQUIRE(accretion::test::runCommand(accretion::test::programPath() + " plan " + scene +
                                            " -D geometry.alpha=\\\"disc\\\" -D shading.visibility=false", out) == 0);
    CHECK_THAT(out, Catch::Matches("(.|\n)*alpha filter callbacks +runs +disc alpha(.|\n)*"));
    CHECK_THAT(out, Catch::Matches("(.|\n)*shadow rays +skipped +visibility off: no shadow rays(.|\n)*"));
    REQUIRE(accretion::test::runCommand(accretion::test::programPath() + " plan " + scene +
                                            " -D render.estimator=\\\"restir\\\" --frames 0:1", out) == 0);
    CHECK_THAT(out, Catch::Matches("(.|\n)*temporalResampling +skipped +one frame: no history buffers or motion(.|\n)*"));
    CHECK(accretion::test::runCommand(accretion::test::programPath() + " plan no_such_scene.toml", out) == 1);
    CHECK_THAT(out, Catch::Contains("no_such_scene.toml"));
}

TEST_CASE("docs/rendering.md carries the estimator table accretion estimators prints", "[cli][docs]") {
    std::string out;
    REQUIRE(accretion::test::runCommand(accretion::test::programPath() + " estimators", out) == 0);
    std::ifstream docs(std::string(ACCRETION_SOURCE_DIR) + "/docs/rendering.md");
    REQUIRE(docs);
    const std::string text((std::istreambuf_iterator<char>(docs)), std::istreambuf_iterator<char>());
    CHECK_THAT(out, Catch::StartsWith("| estimator |"));
    CHECK_THAT(text, Catch::Contains(out));
    for (const char* name : {"exact", "uniform", "power", "ris", "restir", "tree", "split"})
        CHECK_THAT(out, Catch::Contains(std::string("| `") + name + "` |"));
}

TEST_CASE("a camera file written from the orbit path renders bit-identically to orbit, in every convention",
          "[cli][camera][determinism]") {
    const auto dir = accretion::test::scratchDir("camera_file_orbit");
    const std::string scene = "[particles]\ncount = 1500\n[camera]\nwidth = 96\nheight = 54\n";
    std::ofstream(dir / "orbit.toml") << scene << "path = \"orbit\"\norbit_speed = 9\n";
    const std::string estimator = GENERATE("uniform", "restir");
    std::string out;
    const std::string common = " --quiet --frames 0:3 --spp 2 --estimator " + estimator;
    REQUIRE(accretion::test::runCommand(kBin + " render " + (dir / "orbit.toml").string() + common + " -o " +
                                            (dir / "orbit.{frame}.exr").string(), out) == 0);
    for (const std::string convention : {"opengl", "d3d", "vulkan"}) {
        INFO(estimator << ", " << convention);
        const std::string cams = (dir / ("cams_" + convention + ".json")).string();
        REQUIRE(accretion::test::runCommand(kBin + " cameras " + (dir / "orbit.toml").string() +
                                                " --frames 0:3 --convention " + convention + " -o " + cams, out) == 0);
        const auto fileScene = dir / ("file_" + convention + ".toml");
        std::ofstream(fileScene) << scene << "file = \"" << cams << "\"\n";
        REQUIRE(accretion::test::runCommand(kBin + " render " + fileScene.string() + common + " -o " +
                                                (dir / (convention + ".{frame}.exr")).string(), out) == 0);
        for (const char* frame : {"0000", "0001", "0002"})
            CHECK(bitIdentical(readPixels(dir / ("orbit." + std::string(frame) + ".exr")),
                               readPixels(dir / (convention + "." + frame + ".exr"))));
    }
}
