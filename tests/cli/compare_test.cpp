// compare as the way in for GPU frames: half-float EXRs with any data
// window, FLIP in the table and the error maps, and {frame} sequences with
// their per-frame CSV and plot; expected values in closed form.
#include <catch2/catch.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/image_metrics.h"
#include "support/cli.h"

using namespace accretion;
using namespace accretion::test;

namespace {

/// An RGB EXR of display size W x H holding the window (x, y, w, h) with
/// value(px, py) in every channel, as half or float.
template <class F>
void writeWindowExr(const std::filesystem::path& file, int W, int H, int x, int y, int w, int h, bool half, F value,
                    const std::string& frame = "") {
    OIIO::ImageSpec spec(w, h, 3, half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.x = x;
    spec.y = y;
    spec.full_width = W;
    spec.full_height = H;
    if (!frame.empty()) spec.attribute("accretion:frame", frame);
    std::vector<float> px;
    for (int py = y; py < y + h; ++py)
        for (int qx = x; qx < x + w; ++qx)
            for (int c = 0; c < 3; ++c) px.push_back(value(qx, py));
    auto out = OIIO::ImageOutput::create(file.string());
    REQUIRE(out);
    REQUIRE(out->open(file.string(), spec));
    REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    REQUIRE(out->close());
}

double field(const std::string& out, const std::string& key) {
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
        if (line.rfind(key + " ", 0) == 0) return std::stod(line.substr(key.size() + 1));
    FAIL("no " << key << " in:\n" << out);
    return 0.0;
}

}  // namespace

TEST_CASE("compare measures the pixels both data windows hold, half or float", "[cli][compare]") {
    const auto dir = scratchDir("compare_window");
    // Reference: 8x6, float, 1 everywhere. GPU frame: half, the window 5x3 at
    // (2, 1), 1.5 (exact in half) at x >= 4, else 1.
    writeWindowExr(dir / "ref.exr", 8, 6, 0, 0, 8, 6, false, [](int, int) { return 1.0f; });
    writeWindowExr(dir / "gpu.exr", 8, 6, 2, 1, 5, 3, true, [](int x, int) { return x >= 4 ? 1.5f : 1.0f; });
    std::string out;
    const std::string cmd = kBin + " compare " + (dir / "gpu.exr").string() + " " + (dir / "ref.exr").string() +
                            " --flip none --error-map " + (dir / "err.exr").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    CHECK_THAT(out, Contains("compared the 5x3 pixels at (2, 1)"));
    // 9 of 15 pixels differ by 0.5: MSE = 9/15 * 0.25, relMSE = MSE / 1.01.
    CHECK(field(out, "MSE") == Approx(0.15).epsilon(1e-6));
    CHECK(field(out, "relMSE") == Approx(0.15 / 1.01).epsilon(1e-6));
    // 6 of 15 equal the reference; the other 9 are 50% off: outside 1e-4, inside --tolerance 0.5.
    CHECK(field(out, "identical lit pixels (fraction)") == Approx(6.0 / 15.0));
    CHECK(field(out, "lit pixels within tolerance (fraction)") == Approx(6.0 / 15.0));
    std::string loose;
    REQUIRE(runCommand(kBin + " compare " + (dir / "gpu.exr").string() + " " + (dir / "ref.exr").string() +
                           " --flip none --tolerance 0.5", loose) == 0);
    CHECK(field(loose, "lit pixels within tolerance (fraction)") == Approx(1.0));
    CHECK(field(loose, "identical lit pixels (fraction)") == Approx(6.0 / 15.0));
    // Black in both (a background) is no agreement: only the 9 lit pixels count, none identical.
    writeWindowExr(dir / "ref_dark.exr", 8, 6, 0, 0, 8, 6, false, [](int x, int) { return x >= 4 ? 1.0f : 0.0f; });
    writeWindowExr(dir / "gpu_dark.exr", 8, 6, 2, 1, 5, 3, true, [](int x, int) { return x >= 4 ? 1.5f : 0.0f; });
    std::string dark;
    REQUIRE(runCommand(kBin + " compare " + (dir / "gpu_dark.exr").string() + " " + (dir / "ref_dark.exr").string() +
                           " --flip none --json", dark) == 0);
    const auto j = nlohmann::json::parse(dark.substr(dark.find('{')));
    CHECK(j["lit_pixels"] == 9);
    CHECK(j["identical"] == 0.0);
    // The error map is that window of the display window.
    auto in = OIIO::ImageInput::open((dir / "err.exr").string());
    REQUIRE(in);
    CHECK(in->spec().x == 2);
    CHECK(in->spec().y == 1);
    CHECK(in->spec().width == 5);
    CHECK(in->spec().full_width == 8);
    const RgbLayer e = readExrChannels(dir / "err.exr", {"error.R", "error.G", "error.B"});
    CHECK(e.window(4, 2, 1, 1)[0].x == 0.5f);
    CHECK(e.window(3, 2, 1, 1)[0].x == 0.0f);
    // Windows that share nothing: one clear error.
    writeWindowExr(dir / "far.exr", 8, 6, 0, 0, 2, 1, true, [](int, int) { return 1.0f; });
    writeWindowExr(dir / "far_ref.exr", 8, 6, 5, 4, 3, 2, false, [](int, int) { return 1.0f; });
    REQUIRE(runCommand(kBin + " compare " + (dir / "far.exr").string() + " " + (dir / "far_ref.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("share no pixel"));
    // A non-finite pixel is located in display coordinates.
    writeWindowExr(dir / "nan.exr", 8, 6, 2, 1, 5, 3, true,
                   [](int x, int y) { return x == 5 && y == 3 ? std::numeric_limits<float>::quiet_NaN() : 1.0f; });
    REQUIRE(runCommand(kBin + " compare " + (dir / "nan.exr").string() + " " + (dir / "ref.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("1 of 15 pixels are NaN or infinite (at (5, 3)"));
}

TEST_CASE("compare: FLIP in the table and the error map", "[cli][compare][flip]") {
    const auto dir = scratchDir("compare_flip");
    writeWindowExr(dir / "ref.exr", 40, 30, 0, 0, 40, 30, false, [](int x, int) { return x < 20 ? 0.2f : 2.0f; });
    writeWindowExr(dir / "same.exr", 40, 30, 0, 0, 40, 30, false, [](int x, int) { return x < 20 ? 0.2f : 2.0f; });
    writeWindowExr(dir / "off.exr", 40, 30, 0, 0, 40, 30, true, [](int x, int) { return x < 24 ? 0.2f : 2.0f; });
    std::string out;
    REQUIRE(runCommand(kBin + " compare " + (dir / "same.exr").string() + " " + (dir / "ref.exr").string(), out) == 0);
    CHECK(field(out, "HDR-FLIP") == 0.0);
    REQUIRE(runCommand(kBin + " compare " + (dir / "off.exr").string() + " " + (dir / "ref.exr").string() + " --error-map " +
                           (dir / "e.exr").string(), out) == 0);
    INFO(out);
    const double hdr = field(out, "HDR-FLIP");
    CHECK(hdr > 0.05);  // a moved edge: 4 of 40 columns wrong, and the edge's features
    CHECK(hdr < 0.5);
    const RgbLayer f = readExrChannels(dir / "e.exr", {"flip", "flip", "flip"});
    CHECK(f.rgb[15 * 40 + 22].x > 0.5f);  // where the images differ by 10x
    CHECK(f.rgb[15 * 40 + 5].x < 0.01f);  // far from the edge, equal
    REQUIRE(runCommand(kBin + " compare " + (dir / "off.exr").string() + " " + (dir / "ref.exr").string() + " --flip ldr", out) == 0);
    CHECK(field(out, "LDR-FLIP") > 0.0);
    REQUIRE(runCommand(kBin + " compare " + (dir / "off.exr").string() + " " + (dir / "ref.exr").string() + " --flip nope", out) == 1);
    CHECK_THAT(out, Contains("--flip nope: expected hdr, ldr or none"));
}

TEST_CASE("compare a {frame} sequence: per-frame CSV with flicker, and a plot", "[cli][compare]") {
    const auto dir = scratchDir("compare_sequence");
    // Reference 1; GPU frames off by 0.1, 0.2, 0.2, 0.1 everywhere.
    const float off[4] = {0.1f, 0.2f, 0.2f, 0.1f};
    for (int f = 0; f < 4; ++f) {
        const std::string n = fmt::format("{:04d}", f);
        writeWindowExr(dir / ("ref." + n + ".exr"), 6, 4, 0, 0, 6, 4, false, [](int, int) { return 1.0f; }, std::to_string(f));
        writeWindowExr(dir / ("gpu." + n + ".exr"), 6, 4, 0, 0, 6, 4, false, [&](int, int) { return 1.0f + off[f]; },
                       std::to_string(f));
    }
    std::string out;
    const std::string cmd = kBin + " compare '" + (dir / "gpu.{frame}.exr").string() + "' '" + (dir / "ref.{frame}.exr").string() +
                            "' --frames 0:4 --flip none --csv " + (dir / "seq.csv").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    std::ifstream csv(dir / "seq.csv");
    std::string header, line;
    std::getline(csv, header);
    CHECK(header.rfind("frame,relMSE,MSE,MAPE,flip,flicker,tracked,nonfinite_pixels", 0) == 0);
    std::vector<std::vector<std::string>> rows;
    while (std::getline(csv, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
        rows.push_back(cells);
    }
    REQUIRE(rows.size() == 4);
    for (int f = 0; f < 4; ++f) {
        const double e = double(1.0f + off[f]) - 1.0;
        CHECK(std::stoi(rows[f][0]) == f);
        CHECK(std::stod(rows[f][1]) == Approx(e * e / 1.01).epsilon(1e-6));
    }
    // Flicker: the change of the error from the previous frame, relative.
    CHECK(rows[0][5] == "nan");
    const double d = double(1.2f) - double(1.1f);
    CHECK(std::stod(rows[1][5]) == Approx(d * d / 1.01).epsilon(1e-5));
    CHECK(std::stod(rows[2][5]) == 0.0);
    CHECK(std::stod(rows[1][6]) == 1.0);  // no particle.id: every pixel is compared
    CHECK(std::filesystem::file_size(dir / "seq.png") > 1000);
    // A pattern without {frame}: one clear error.
    REQUIRE(runCommand(kBin + " compare " + (dir / "gpu.0000.exr").string() + " '" + (dir / "ref.{frame}.exr").string() +
                           "' --frames 0:4 --csv " + (dir / "x.csv").string(), out) == 1);
    CHECK_THAT(out, Contains("has no {frame} pattern"));
}

TEST_CASE("compare --layer of one channel (spp) reads it in all three components", "[cli][compare]") {
    // Two power renders of 8 and 16 samples: spp is 8 or 16 on a hit pixel and
    // 0 on a miss, so relMSE = hits / pixels * 8^2 / (16^2 + 1e-2), with the
    // hit count counted here from the particle ids the render wrote.
    const auto dir = scratchDir("compare_spp");
    std::string out;
    for (int spp : {8, 16})
        REQUIRE(runCommand(kBin + " render " + kScenes + "/quickstart.toml -D camera.width=64 -D camera.height=36 " +
                               "--estimator power --spp " + std::to_string(spp) + " --frames 0:1 --quiet -o " +
                               (dir / ("s" + std::to_string(spp) + ".{frame}.exr")).string(),
                           out) == 0);
    const std::vector<std::uint32_t> ids = readExrUintChannel(dir / "s8.0000.exr", "particle.id");
    REQUIRE(ids.size() == 64 * 36);
    const double hits = double(std::count_if(ids.begin(), ids.end(), [](std::uint32_t id) { return id != 0xffffffffu; }));
    REQUIRE(hits > 0.0);
    const std::string cmd = kBin + " compare " + (dir / "s8.0000.exr").string() + " " + (dir / "s16.0000.exr").string() +
                            " --layer spp --flip none";
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    CHECK(field(out, "relMSE") == Approx(hits / (64.0 * 36.0) * 64.0 / (256.0 + 1e-2)).epsilon(1e-9));
    CHECK(field(out, "MSE") == Approx(hits / (64.0 * 36.0) * 64.0).epsilon(1e-7));  // printed to 9 digits
    REQUIRE(runCommand(kBin + " compare " + (dir / "s8.0000.exr").string() + " " + (dir / "s8.0000.exr").string() +
                           " --layer spp --flip none",
                       out) == 0);
    CHECK(field(out, "relMSE") == 0.0);
}

TEST_CASE("compare's worst pixels are ready-to-run render --pixel commands that explain those pixels", "[cli][compare]") {
    const auto dir = scratchDir("compare_worst");
    std::string out;
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact -o " + (dir / "ref.exr").string(), out) == 0);
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator uniform --spp 1 -o " + (dir / "x.exr").string(), out) ==
            0);
    REQUIRE(runCommand(kBin + " compare " + (dir / "x.exr").string() + " " + (dir / "ref.exr").string() + " --flip none", out) == 0);
    INFO(out);
    REQUIRE(out.find("worst pixels") != std::string::npos);
    // The first one, as printed: "  <error>  accretion render <ref>.settings.toml --frames 0 --pixel X,Y".
    const auto at = out.find("accretion render ", out.find("worst pixels"));
    REQUIRE(at != std::string::npos);
    const std::string command = out.substr(at + std::string("accretion ").size(), out.find('\n', at) - at - 10);
    CHECK_THAT(command, Contains((dir / "ref.settings.toml").string()));
    const auto pixel = command.substr(command.find("--pixel ") + 8);
    const std::string xy = pixel.substr(0, pixel.find(','));
    std::string explained;
    REQUIRE(runCommand(kBin + " " + command + " --quiet", explained) == 0);
    INFO(explained);
    CHECK_THAT(explained, Contains("pixel (" + xy + ", " + pixel.substr(pixel.find(',') + 1) + ") of frame 0, exact estimator"));
}

TEST_CASE("compare's worst pixels never name a settings file that a later run rewrote", "[cli][compare]") {
    const auto dir = scratchDir("compare_worst_stale");
    std::string out;
    // ref.0000.exr and its ref.settings.toml, then a later run of the same
    // {frame} name at another field of view: it rewrites ref.settings.toml.
    const std::string ref = (dir / "ref.{frame}.exr").string();
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact --frames 0:1 -o " + ref, out) == 0);
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator uniform --spp 1 -o " + (dir / "x.exr").string(), out) ==
            0);
    const std::string compare = kBin + " compare " + (dir / "x.exr").string() + " " + (dir / "ref.0000.exr").string() + " --flip none";
    REQUIRE(runCommand(compare, out) == 0);
    CHECK_THAT(out, Contains("accretion render " + (dir / "ref.settings.toml").string()));
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact --frames 1:2 -D camera.fov=30 -o " + ref, out) == 0);
    REQUIRE(runCommand(compare, out) == 0);
    INFO(out);
    CHECK(out.find("accretion render ") == std::string::npos);  // a command would render another view
    CHECK_THAT(out, Contains("ref.settings.toml is not the settings the reference records: a later run rewrote it"));
}
