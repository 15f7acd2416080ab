// render --crop and render --pixel against the full render of the same
// command line: the window is the same pixels bit for bit, and the pixel
// report prints the full render's floats.
#include <catch2/catch.hpp>

#include <cstring>
#include <regex>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

using namespace accretion;
using namespace accretion::test;

namespace {

struct Exr {
    int x = 0, y = 0, width = 0, height = 0, fullWidth = 0, fullHeight = 0, channels = 0;
    std::vector<std::string> names;
    std::vector<std::uint32_t> bits;  ///< native 4-byte values, interleaved
    std::uint32_t at(int px, int py, const std::string& channel) const {
        const auto c = std::find(names.begin(), names.end(), channel) - names.begin();
        return bits[(std::size_t(py - y) * width + (px - x)) * channels + c];
    }
};

Exr readExr(const std::filesystem::path& file) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const OIIO::ImageSpec& s = in->spec();
    Exr e{s.x, s.y, s.width, s.height, s.full_width, s.full_height, s.nchannels, s.channelnames, {}};
    e.bits.resize(std::size_t(s.width) * s.height * s.nchannels);
    REQUIRE(in->read_image(0, 0, 0, s.nchannels, OIIO::TypeDesc::UNKNOWN, e.bits.data()));
    return e;
}

std::string scene() {
    return kBin + " render " + kScenes + "/quickstart.toml --quiet -D particles.count=1500 -D camera.width=96 -D camera.height=54";
}

/// Extra options per estimator: restir over three frames (temporal and
/// spatial reuse, its history the whole frame's); tree adaptive; split with
/// the pilot's k; "counting": power with the GPU counters (the whole frame's
/// dispatch, its heatmap layers cut to the window).
std::string options(const std::string& estimator) {
    if (estimator == "restir") return " --estimator restir --frames 0:3 -D restir.bias_correction=\"pairwise\"";
    if (estimator == "tree") return " --estimator tree --frames 0:1 --spp 4 --target-stderr 5% -D render.max_samples=32";
    if (estimator == "split") return " --estimator split --frames 0:1 --spp 6 -D render.near_lights=0";
    if (estimator == "counting") return " --estimator power --frames 0:1 --spp 4 -D gpu.counters=true";
    return " --estimator " + estimator + " --frames 0:1 --spp 6";
}

std::vector<std::string> listing(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::string lastFrame(const std::string& estimator) { return estimator == "restir" ? ".0002.exr" : ".0000.exr"; }

}  // namespace

TEST_CASE("render --crop writes the window of the full render as the EXR's data window", "[cli][window]") {
    const auto dir = scratchDir("crop");
    const std::string estimator = GENERATE("exact", "power", "uniform", "ris", "tree", "split", "restir", "counting");
    std::string out;
    const std::string base = scene() + options(estimator);
    REQUIRE(runCommand(base + " -o " + (dir / "full.{frame}.exr").string(), out) == 0);
    // A window crossing 8x8 tile borders on every side, and a one-pixel column at the right edge.
    for (const auto& [crop, x0, x1, y0, y1] : {std::tuple{"13,70,5,42", 13, 70, 5, 42}, std::tuple{"95,96,0,54", 95, 96, 0, 54}}) {
        INFO(estimator << " --crop " << crop);
        REQUIRE(runCommand(base + " --crop " + crop + " -o " + (dir / "crop.{frame}.exr").string(), out) == 0);
        const Exr full = readExr(dir / ("full" + lastFrame(estimator)));
        const Exr win = readExr(dir / ("crop" + lastFrame(estimator)));
        CHECK(win.x == x0);
        CHECK(win.y == y0);
        CHECK(win.width == x1 - x0);
        CHECK(win.height == y1 - y0);
        CHECK(win.fullWidth == 96);
        CHECK(win.fullHeight == 54);
        REQUIRE(win.names == full.names);
        std::size_t differing = 0, hits = 0;
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
                hits += full.at(x, y, "particle.id") != 0xffffffffu;
                for (const std::string& c : full.names) differing += full.at(x, y, c) != win.at(x, y, c);
            }
        CHECK(differing == 0);
        if (x1 - x0 > 1) CHECK(hits > 100);  // the window shows the disk, not only background
        // The previews are of the window.
        auto png = OIIO::ImageInput::open((dir / ("crop" + lastFrame(estimator))).replace_extension(".png").string());
        REQUIRE(png);
        CHECK(png->spec().width == x1 - x0);
        CHECK(png->spec().height == y1 - y0);
    }
}

TEST_CASE("render --pixel prints the full render's pixel bit for bit", "[cli][window]") {
    const auto dir = scratchDir("pixel");
    const std::string estimator = GENERATE("exact", "power", "ris", "split", "restir");
    std::string out;
    const std::string base = scene() + options(estimator);
    REQUIRE(runCommand(base + " -o " + (dir / "full.{frame}.exr").string(), out) == 0);
    const Exr full = readExr(dir / ("full" + lastFrame(estimator)));
    // Three hit pixels (first, middle and last in scan order) and a miss.
    std::vector<std::pair<int, int>> hit, miss;
    for (int y = 0; y < full.height; ++y)
        for (int x = 0; x < full.width; ++x) (full.at(x, y, "particle.id") != 0xffffffffu ? hit : miss).push_back({x, y});
    REQUIRE(hit.size() > 100);
    REQUIRE(!miss.empty());
    const std::vector<std::string> before = listing(dir);
    for (const auto& [x, y] : {hit.front(), hit[hit.size() / 2], hit.back(), miss.front()}) {
        const std::string cmd = base + " --pixel " + std::to_string(x) + "," + std::to_string(y);
        INFO(cmd);
        REQUIRE(runCommand(cmd, out) == 0);
        INFO(out);
        // "  L = (a, b, c)" and the other values: the shortest decimals that
        // read back to the same float.
        const auto check = [&](const std::string& label, const char* const channels[3]) {
            const std::regex re("\n *" + label + " = \\(([^,]+), ([^,]+), ([^)]+)\\)");
            std::smatch m;
            REQUIRE(std::regex_search(out, m, re));
            for (int c = 0; c < 3; ++c) {
                const float printed = std::strtof(m[c + 1].str().c_str(), nullptr);
                CHECK(std::bit_cast<std::uint32_t>(printed) == full.at(x, y, channels[c]));
            }
        };
        static const char* const L[3] = {"R", "G", "B"};
        static const char* const Lr[3] = {"Lr.R", "Lr.G", "Lr.B"};
        check("L", L);
        if (full.at(x, y, "particle.id") == 0xffffffffu) {
            CHECK_THAT(out, Contains("hit: none"));
            continue;
        }
        check("Lr", Lr);
        CHECK_THAT(out, Contains("hit: particle " + std::to_string(full.at(x, y, "particle.id"))));
        if (estimator == std::string("exact")) CHECK_THAT(out, Contains("(the pixel's Lr: bit-equal)"));
        if (estimator == std::string("power")) CHECK_THAT(out, Contains("6 light samples"));
        if (estimator == std::string("split")) CHECK_THAT(out, Contains("nearest lights summed exactly"));
        if (estimator == std::string("ris")) CHECK_THAT(out, Contains("6 reservoirs (RIS)"));
        if (estimator == std::string("restir")) CHECK_THAT(out, Contains("spatialResampling"));
    }
    CHECK(listing(dir) == before);  // --pixel writes nothing
}

TEST_CASE("a crop of a 16384x16384 image holds its window alone: it fits where the whole image is refused", "[cli][window]") {
    const auto dir = scratchDir("crop_huge");
    const std::string base = kBin + " render " + kScenes + "/quickstart.toml --quiet -D particles.count=1500 --frames 0:1 "
                             "--estimator split --spp 4 -D camera.width=16384 -D camera.height=16384 -D render.memory_limit_mb=2000";
    std::string out;
    // The whole image: about 330 B a pixel, 88 GB, over the limit (on any machine).
    REQUIRE(runCommand(base + " -o " + (dir / "whole.{frame}.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("at 16384x16384 need about") && Contains("more than the limit of 2000 MB"));
    REQUIRE(runCommand(base + " --crop 8000,8064,8000,8032 -o " + (dir / "crop.{frame}.exr").string(), out) == 0);
    const Exr win = readExr(dir / "crop.0000.exr");
    CHECK(win.fullWidth == 16384);
    CHECK(win.fullHeight == 16384);
    CHECK(win.width == 64);
    CHECK(win.height == 32);
    // Its memory is the particles' and libraries', not the image's (a whole-image G-buffer alone is 11.8 GB).
    const auto stats = nlohmann::json::parse(readFile(dir / "crop.stats.json"));
    CHECK(stats.at("peak_rss_bytes").get<double>() < 300e6);
}
