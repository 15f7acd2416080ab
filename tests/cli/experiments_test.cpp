// compare, converge and bias as a user runs them: real processes, real EXR
// files read back with OpenImageIO.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <map>
#include <set>

#include <fstream>
#include <regex>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/image_metrics.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/gpu_frame_file.h"
#include "support/cli.h"

using namespace accretion;
using namespace accretion::test;

namespace {


void writeConstant(const std::filesystem::path& file, float value) {
    const std::size_t pixels = 4 * 3;
    std::vector<FloatChannel> ch = {{"R", std::vector<float>(pixels, value)}, {"G", std::vector<float>(pixels, value)},
                                    {"B", std::vector<float>(pixels, value)}};
    writeChannelsExr(file, 4, 3, ch, {});
}

std::vector<std::vector<std::string>> readCsv(const std::filesystem::path& file) {
    std::ifstream in(file);
    REQUIRE(in);
    std::vector<std::vector<std::string>> rows;
    for (std::string line; std::getline(in, line);) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
        rows.push_back(cells);
    }
    return rows;
}

}  // namespace

TEST_CASE("compare prints relMSE, MSE and MAPE against the second image", "[cli][experiments]") {
    const auto dir = accretion::test::scratchDir("compare");
    writeConstant(dir / "ref.exr", 1.0f);
    writeConstant(dir / "x.exr", 1.1f);
    std::string out;
    REQUIRE(runCommand(kBin + " compare " + (dir / "x.exr").string() + " " + (dir / "ref.exr").string(), out) == 0);
    // Closed form with d = 0.1 (as float), ref = 1, eps = 1e-2.
    const double d = double(1.1f) - 1.0;
    double rel = 0, mse = 0, mape = 0;
    // After the warning that these images (written here, no metadata) could not be checked for their view.
    CHECK_THAT(out, Contains("frame, scene, camera (worldToCamera), projection (worldToNDC), jitter, scene settings not checked"));
    REQUIRE(out.find("relMSE") != std::string::npos);
    REQUIRE(std::sscanf(out.c_str() + out.find("relMSE"), "relMSE %lf\nMSE %lf\nMAPE %lf", &rel, &mse, &mape) == 3);
    CHECK(rel == Approx(d * d / 1.01).epsilon(1e-6));
    CHECK(mse == Approx(d * d).epsilon(1e-6));
    CHECK(mape == Approx(d / 1.01).epsilon(1e-6));
    REQUIRE(runCommand(kBin + " compare --json " + (dir / "ref.exr").string() + " " + (dir / "ref.exr").string(), out) == 0);
    CHECK_THAT(out, Contains("\"relMSE\": 0.0") && Contains("\"MAPE\": 0.0"));
    // Different sizes: an error naming the file, exit 1.
    writeChannelsExr(dir / "small.exr", 2, 2, {{"R", std::vector<float>(4)}, {"G", std::vector<float>(4)}, {"B", std::vector<float>(4)}}, {});
    CHECK(runCommand(kBin + " compare " + (dir / "small.exr").string() + " " + (dir / "ref.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("small.exr"));
}

TEST_CASE("converge: error falls with effort, CSV and plot written", "[cli][experiments]") {
    const auto dir = accretion::test::scratchDir("converge");
    std::string out;
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --frames 20:21 --quiet --estimator exact -o " + (dir / "exact.exr").string(),
                       out) == 0);
    const std::string cmd = kBin + " converge " + tinyScene() + " --quiet --reference " + (dir / "exact.exr").string() +
                            " --frame 20 --estimators uniform,tree,restir:pairwise --budget 3s --max-effort 64 -o " + (dir / "c").string();
    INFO(cmd << "\n" << out);
    REQUIRE(runCommand(cmd, out) == 0);
    const auto rows = readCsv(dir / "c.csv");
    REQUIRE(rows.size() > 4);
    REQUIRE(rows[0][0] == "estimator");
    REQUIRE(rows[0][7] == "relMSE");
    std::map<std::string, std::vector<double>> rel;
    for (std::size_t k = 1; k < rows.size(); ++k) rel[rows[k][0]].push_back(std::stod(rows[k][7]));
    REQUIRE(rel.size() == 3);
    // The exact reference has no noise: relMSE of uniform at the largest effort
    // is well below that at 1 spp (Monte Carlo: ~1/spp).
    REQUIRE(rel["uniform"].size() >= 4);
    CHECK(rel["uniform"].back() < 0.25 * rel["uniform"].front());
    CHECK(std::filesystem::exists(dir / "c.json"));
    CHECK(std::filesystem::exists(dir / "c.png"));
}

TEST_CASE("bias: 1/M restir is flagged, uniform Monte Carlo is not", "[cli][experiments][statistical][long]") {
    const auto dir = accretion::test::scratchDir("bias");
    std::string out;
    // restir measured at steady state (the default history: ceil(m_cap) = 20 frames before the measured one).
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --frames 20:21 --quiet --estimator exact -o " + (dir / "exact.exr").string(),
                       out) == 0);
    const std::string run = kBin + " bias " + tinyScene() + " -D render.samples=16 --quiet --reference " +
                            (dir / "exact.exr").string() +
                            " --frame 20 --estimators uniform,restir:none,uniform:render.samples=64 --seeds 24 -o " + (dir / "b").string();
    INFO(run << "\n" << out);
    REQUIRE(runCommand(run, out) == 0);
    const auto rows = readCsv(dir / "b.csv");
    REQUIRE(rows.size() == 4);
    const auto col = [&](const char* name) {
        const auto i = std::find(rows[0].begin(), rows[0].end(), name);
        REQUIRE(i != rows[0].end());
        return std::size_t(i - rows[0].begin());
    };
    const std::size_t biased = col("biased"), loss = col("energy_loss_pct"), relMse = col("rel_mse"),
                      perFrame = col("seconds_per_frame"), perRender = col("seconds_per_render"), bound = col("detectable_bias_pct");
    // Verdict at |z| > 3.29 (99.9%): the unbiased estimator passes (false
    // alarm 1e-3), 1/M normalisation loses energy and is flagged.
    CHECK(rows[1][0] == "uniform");
    CHECK(rows[1][biased] == "0");
    CHECK(rows[2][0] == "restir:none");
    CHECK(rows[2][biased] == "1");
    CHECK(std::stod(rows[2][loss]) > 0.0);  // energy loss, not gain
    // relMSE per render: unbiased Monte Carlo's falls as 1 / samples, so 4x
    // the samples give a quarter (0.15 to 0.4: 24 seeds of a noisy estimate);
    // restir's history frames are not in its s/frame.
    const double r16 = std::stod(rows[1][relMse]), r64 = std::stod(rows[3][relMse]);
    INFO("relMSE at 16 and 64 spp: " << r16 << ", " << r64);
    CHECK(r16 > 0.0);
    CHECK((r64 / r16 > 0.15 && r64 / r16 < 0.4));
    CHECK(std::stod(rows[2][perFrame]) < std::stod(rows[2][perRender]));
    // The history each row rendered: restir's steady state, none for Monte Carlo.
    CHECK(rows[1][col("history_frames")] == "0");
    CHECK(rows[2][col("history_frames")] == "20");
    // The anatomy of the error: with every light visible, against a reference
    // without visibility, the error left is light selection's; shadow rays add
    // their own noise, so it is smaller, and the rest is visibility's share.
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " -D shading.visibility=false --frames 20:21 --quiet --estimator exact -o " +
                           (dir / "unshadowed.exr").string(), out) == 0);
    REQUIRE(runCommand(kBin + " bias " + tinyScene() + " -D render.samples=16 --quiet --reference " + (dir / "exact.exr").string() +
                           " --unshadowed-reference " + (dir / "unshadowed.exr").string() +
                           " --frame 20 --estimators uniform,restir:pairwise --seeds 8 -o " + (dir / "anatomy").string(), out) == 0);
    const auto anatomy = readCsv(dir / "anatomy.csv");
    REQUIRE(anatomy.size() == 3);
    for (std::size_t r = 1; r < 3; ++r) {
        const double all = std::stod(anatomy[r][col("rel_mse")]), unshadowed = std::stod(anatomy[r][col("rel_mse_unshadowed")]);
        INFO(anatomy[r][0] << ": relMSE " << all << ", with every light visible " << unshadowed);
        CHECK((unshadowed > 0.0 && unshadowed < all));
        CHECK(std::stod(anatomy[r][col("visibility_share_pct")]) == Approx(100.0 * (all - unshadowed) / all).epsilon(1e-3));
        CHECK(std::stod(anatomy[r][col("light_selection_share_pct")]) == Approx(100.0 * unshadowed / all).epsilon(1e-3));
    }
    // Short of it, a measurement is refused rather than made at another operating point.
    CHECK(runCommand(kBin + " bias " + tinyScene() + " --quiet --reference " + (dir / "exact.exr").string() +
                         " --frame 19 --estimators restir --seeds 2 -o " + (dir / "short").string(), out) == 1);
    CHECK_THAT(out, Contains("--history steady: restir needs 20 history frames before frame 19"));
    // The bias a run can see falls with its noise: 4x the samples, half the
    // standard error of the image's mean (0.5; below 0.8 with 24 seeds' spread).
    const double b16 = std::stod(rows[1][bound]), b64 = std::stod(rows[3][bound]);
    INFO("detectable bias at 16 and 64 spp: " << b16 << "%, " << b64 << "%");
    CHECK((b64 > 0.0 && b64 < 0.8 * b16));
    CHECK(std::filesystem::exists(dir / "b.restir_none.exr"));
    CHECK(std::filesystem::exists(dir / "b.png"));
}

TEST_CASE("bias: relMSE's standard error is the spread of the seeds' own relMSE", "[cli][experiments]") {
    // Four seeds in one run (render.seed 100-103) against the same seeds in
    // two runs of two: a run of two seeds a, b gives their mean m and
    // standard error |a - b| / 2, so a, b = m -+ se. The four-seed run's
    // relMSE is the mean of those four values and its standard error
    // sd / sqrt(4), sd their sample standard deviation (closed forms of the
    // two runs' figures; CSV's 6 digits).
    const auto dir = accretion::test::scratchDir("bias_relmse_se");
    std::string out;
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact -o " + (dir / "exact.exr").string(), out) == 0);
    const auto run = [&](std::uint32_t seed, std::uint32_t seeds, const std::string& name) {
        const std::string cmd = kBin + " bias " + tinyScene() + " -D render.samples=4 -D render.seed=" + std::to_string(seed) +
                                " --quiet --reference " + (dir / "exact.exr").string() + " --frame 0 --estimators uniform --seeds " +
                                std::to_string(seeds) + " -o " + (dir / name).string();
        INFO(cmd << "\n" << out);
        REQUIRE(runCommand(cmd, out) == 0);
        const auto rows = readCsv(dir / (name + ".csv"));
        REQUIRE(rows.size() == 2);
        const auto col = [&](const char* c) {
            const auto i = std::find(rows[0].begin(), rows[0].end(), c);
            REQUIRE(i != rows[0].end());
            return std::size_t(i - rows[0].begin());
        };
        return std::pair<double, double>(std::stod(rows[1][col("rel_mse")]), std::stod(rows[1][col("rel_mse_stderr")]));
    };
    const auto [all, se] = run(100, 4, "four");
    std::vector<double> one;
    for (const std::uint32_t first : {100u, 102u}) {
        const auto [m, s] = run(first, 2, "two" + std::to_string(first));
        CHECK(s > 0.0);
        one.push_back(m - s);
        one.push_back(m + s);
    }
    double mean = 0.0, ss = 0.0;
    for (const double r : one) mean += r / 4.0;
    for (const double r : one) ss += (r - mean) * (r - mean);
    const double sd = std::sqrt(ss / 3.0);
    INFO("relMSE " << all << " +- " << se << "; the seeds' " << one[0] << ", " << one[1] << ", " << one[2] << ", " << one[3]);
    CHECK(all == Approx(mean).epsilon(1e-5));
    CHECK(se == Approx(sd / 2.0).epsilon(1e-3));
}

TEST_CASE("experiment and restir input errors: one clear message, exit 1", "[cli][errors]") {
    const auto dir = accretion::test::scratchDir("experiment_errors");
    std::string out;
    CHECK(runCommand(kBin + " converge " + tinyScene() + " --reference nothere.exr --estimators uniform", out) == 1);
    CHECK_THAT(out, Contains("nothere.exr"));
    CHECK(runCommand(kBin + " bias " + tinyScene() + " --reference x.exr --estimators unifrom", out) == 1);
    CHECK_THAT(out, Contains("--estimators 'unifrom': unknown estimator"));
    CHECK(runCommand(kBin + " bias " + tinyScene() + " --reference x.exr --estimators uniform:pairwise", out) == 1);
    CHECK_THAT(out, Contains("restir only"));
    // 800 particles need 10 light-index bits; 8 are rejected before any output is written.
    const auto exr = dir / "r.exr";
    CHECK(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator restir -D restir.layout=\"packed\" "
                     "-D restir.light_bits=8 -o " + exr.string(), out) == 1);
    CHECK_THAT(out, Contains("needs 10 bits"));
    CHECK_FALSE(std::filesystem::exists(exr));
    CHECK(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator tree --target-stderr 5x -o " + exr.string(), out) == 1);
    CHECK_THAT(out, Contains("--target-stderr 5x"));
}

TEST_CASE("a restir EXR carries the reservoir AOVs, consistent with the image", "[cli][restir]") {
    const auto dir = accretion::test::scratchDir("restir_aovs");
    std::string out;
    const std::string cmd = kBin + " render " + tinyScene() + " --quiet --estimator restir -D render.frames=3 -o " +
                            (dir / "r.{frame}.exr").string();
    INFO(cmd << "\n" << out);
    REQUIRE(runCommand(cmd, out) == 0);
    auto in = OIIO::ImageInput::open((dir / "r.0002.exr").string());
    REQUIRE(in);
    const OIIO::ImageSpec spec = in->spec();
    const int W = spec.channelindex("restir.W"), M = spec.channelindex("restir.M"),
              light = spec.channelindex("restir.light"), p = spec.channelindex("restir.p_hat"),
              id = spec.channelindex("particle.id"), lr = spec.channelindex("Lr.G");
    REQUIRE(W >= 0);
    REQUIRE(M >= 0);
    REQUIRE(light >= 0);
    REQUIRE(p >= 0);
    CHECK(spec.channelformat(light) == OIIO::TypeDesc::UINT);
    const std::size_t pixels = std::size_t(spec.width) * spec.height;
    std::vector<float> f(pixels * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, f.data()));
    // OIIO normalises integer channels when converting to float: read the id channels as integers.
    std::vector<std::uint32_t> ids(pixels), lights(pixels);
    REQUIRE(in->read_image(0, 0, id, id + 1, OIIO::TypeDesc::UINT, ids.data()));
    REQUIRE(in->read_image(0, 0, light, light + 1, OIIO::TypeDesc::UINT, lights.data()));
    std::size_t withSample = 0;
    for (std::size_t px = 0; px < pixels; ++px) {
        const float* c = &f[px * spec.nchannels];
        if (ids[px] == 0xffffffffu) {
            CHECK(c[W] == 0.0f);
            continue;
        }
        // A pixel with light has a sample with W > 0 and p_hat > 0 that is not its own particle.
        if (c[lr] > 0.0f) {
            CHECK(c[W] > 0.0f);
            CHECK(c[p] > 0.0f);
            CHECK(lights[px] != ids[px]);
            CHECK(lights[px] < 800u);
            ++withSample;
        }
        CHECK(c[M] >= 16.0f);  // at least this frame's candidates
    }
    CHECK(withSample > 100);
}

TEST_CASE("compare: error maps in closed form, a GPU frame's channel names, metadata that differ", "[cli][experiments][compare]") {
    const auto dir = accretion::test::scratchDir("compare_maps");
    // The reference: 1 everywhere with Lr_stderr 0.05; the GPU frame: 1.1 in
    // its own channel names.
    std::vector<FloatChannel> ref = {{"R", std::vector<float>(12, 1.0f)}, {"G", std::vector<float>(12, 1.0f)},
                                     {"B", std::vector<float>(12, 1.0f)}, {"Lr_stderr.R", std::vector<float>(12, 0.05f)},
                                     {"Lr_stderr.G", std::vector<float>(12, 0.05f)}, {"Lr_stderr.B", std::vector<float>(12, 0.05f)}};
    writeChannelsExr(dir / "ref.exr", 4, 3, ref, {{"frame", "0"}});
    std::vector<FloatChannel> gpu = {{"color.r", std::vector<float>(12, 1.1f)}, {"color.g", std::vector<float>(12, 1.1f)},
                                     {"color.b", std::vector<float>(12, 1.1f)}};
    writeChannelsExr(dir / "gpu.exr", 4, 3, gpu, {{"frame", "3"}});
    std::string out;
    const std::string cmd = kBin + " compare " + (dir / "gpu.exr").string() + " " + (dir / "ref.exr").string() +
                            " --channels color.r,color.g,color.b --error-map " + (dir / "err.exr").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    CHECK_THAT(out, Contains("warning") && Contains("frame: 3 here, 0 in the reference"));
    const float d = 1.1f - 1.0f;
    CHECK(readExrChannels(dir / "err.exr", {"error.R", "error.G", "error.B"}).rgb[5].x == Approx(d).epsilon(1e-6));
    CHECK(readExrChannels(dir / "err.exr", {"relative.R", "relative.G", "relative.B"}).rgb[7].y == Approx(d / 1.01).epsilon(1e-5));
    CHECK(readExrChannels(dir / "err.exr", {"z.R", "z.G", "z.B"}).rgb[0].z == Approx(d / 0.05).epsilon(1e-5));
    for (const char* png : {"err.error.png", "err.relative.png", "err.z.png"}) {
        // The image, and under it the colour bar with its scale: a wider, taller PNG.
        auto in = OIIO::ImageInput::open((dir / png).string());
        REQUIRE(in);
        CHECK(in->spec().width >= 360);
        CHECK(in->spec().height == 3 + 74);
        CHECK_THAT(in->spec().get_string_attribute("ImageDescription"), Contains("scale ["));
    }
    // --strict: the other frame is an error, and nothing is written.
    CHECK(runCommand(kBin + " compare " + (dir / "gpu.exr").string() + " " + (dir / "ref.exr").string() +
                         " --channels color.r,color.g,color.b --strict --error-map " + (dir / "strict.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("not the reference's view: frame: 3 here, 0 in the reference (--strict)"));
    CHECK(!std::filesystem::exists(dir / "strict.exr"));
    // The error map never replaces an input.
    CHECK(runCommand(kBin + " compare " + (dir / "gpu.exr").string() + " " + (dir / "ref.exr").string() +
                         " --channels color.r,color.g,color.b --error-map " + (dir / "ref.exr").string(), out) == 1);
    CHECK_THAT(out, Contains("an input of this run"));
}

TEST_CASE("bias --gpu-frames: frames read from files give the figures of rendering them", "[cli][experiments][gpu]") {
    // The OptiX twin's frames reach bias as .gpuframe files holding Lr alone.
    // Written here from the CPU's own restir renders of the same seeds, they
    // must give bias's figures to the last digit: the files are read, not
    // re-rendered, and nothing of the twin is needed.
    const auto dir = accretion::test::scratchDir("bias_gpu_frames");
    std::string out;
    // The reference of the frame measured (bias refuses another frame's).
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact --frames 2 -o " + (dir / "exact.exr").string(),
                       out) == 0);
    for (int seed = 5; seed < 9; ++seed) {
        const auto exr = dir / fmt::format("r{}.0002.exr", seed);
        REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator restir --frames 0:3 -D render.seed=" +
                               std::to_string(seed) + " -o " + (dir / fmt::format("r{}.{{frame}}.exr", seed)).string(), out) == 0);
        const RgbLayer lr = readExrLayer(exr.string(), "Lr");
        GpuFrame g;
        g.width = lr.width;
        g.height = lr.height;
        g.frame = 2;
        g.Lr = lr.rgb;
        g.metadata = {{"seed", std::to_string(seed)}, {"estimator", "restir"}, {"render_time_s", "0.5"}};
        writeGpuFrame(dir / fmt::format("restir_basic.{}.gpuframe", seed), g);
    }
    const std::string common = " bias " + tinyScene() + " --quiet -D render.seed=5 --reference " + (dir / "exact.exr").string() +
                               " --estimators restir:basic --seeds 4 --frame 2 --history 2 -o ";
    REQUIRE(runCommand(kBin + common + (dir / "rendered").string(), out) == 0);
    INFO(out);
    REQUIRE(runCommand(kBin + common + (dir / "read").string() + " --gpu-frames " + (dir / "{estimator}.{seed}.gpuframe").string(),
                       out) == 0);
    const auto rendered = readCsv(dir / "rendered.csv"), read = readCsv(dir / "read.csv");
    REQUIRE(rendered.size() == 2);
    REQUIRE(read.size() == 2);
    for (int col : {2, 3, 4, 5}) CHECK(read[1][col] == rendered[1][col]);  // mean error, stderr, z, energy loss

    // A frame of another seed, or a missing one, is refused naming the file.
    std::filesystem::rename(dir / "restir_basic.8.gpuframe", dir / "restir_basic.9.gpuframe");
    CHECK(runCommand(kBin + common + (dir / "x").string() + " --gpu-frames " + (dir / "{estimator}.{seed}.gpuframe").string(), out) == 1);
    CHECK_THAT(out, Contains("restir_basic.8.gpuframe"));
    std::filesystem::copy_file(dir / "restir_basic.5.gpuframe", dir / "restir_basic.8.gpuframe");
    CHECK(runCommand(kBin + common + (dir / "x").string() + " --gpu-frames " + (dir / "{estimator}.{seed}.gpuframe").string(), out) == 1);
    CHECK_THAT(out, Contains("restir_basic.8.gpuframe: seed 5, expected 8"));
    // The first spec measured, the second's frames missing: exit 1 and no
    // output at all, not the first spec's bias map.
    std::filesystem::remove(dir / "restir_basic.8.gpuframe");
    std::filesystem::rename(dir / "restir_basic.9.gpuframe", dir / "restir_basic.8.gpuframe");
    const std::string two = std::regex_replace(common, std::regex("restir:basic"), "restir:basic,restir:pairwise");
    CHECK(runCommand(kBin + two + (dir / "partial").string() + " --gpu-frames " + (dir / "{estimator}.{seed}.gpuframe").string(),
                     out) == 1);
    CHECK_THAT(out, Contains("restir_pairwise.5.gpuframe"));
    for (const auto& e : std::filesystem::directory_iterator(dir))
        CHECK(e.path().filename().string().rfind("partial", 0) == std::string::npos);
    // Lr alone cannot be imported as render's EXR.
    CHECK(runCommand(kBin + " import-gpu " + (dir / "restir_basic.5.gpuframe").string(), out) == 1);
    CHECK_THAT(out, Contains("holds Lr alone"));
}

TEST_CASE("converge --sequence: flicker is two frames' error where frames are independent, less where reuse keeps it", "[cli][experiments][statistical]") {
    // A static view (no motion): the reference's own change is 0, and the
    // change of an estimate is its two frames' errors. Uniform Monte Carlo
    // draws each frame anew, so its flicker is relMSE(t) + relMSE(t - 1) in
    // expectation (8 seeds of ~6K pixels: within 20%); restir's temporal
    // reuse carries its samples over, so its error persists and flickers less.
    const auto dir = accretion::test::scratchDir("converge_flicker");
    const std::string still = " -D particles.gm=0 -D camera.path=\"static\"";
    std::string out;
    REQUIRE(runCommand(kBin + " render " + tinyScene() + still + " --frames 20:24 --quiet --estimator exact -o " +
                           (dir / "ref.{frame}.exr").string(), out) == 0);
    const std::string cmd = kBin + " converge " + tinyScene() + still + " --quiet --reference " + (dir / "ref.{frame}.exr").string() +
                            " --frame 20 --sequence 4 --seeds 8 --estimators uniform:render.samples=4,restir:pairwise -o " +
                            (dir / "c").string();
    INFO(cmd << "\n" << out);
    REQUIRE(runCommand(cmd, out) == 0);
    const auto rows = readCsv(dir / "c.csv");
    const auto col = [&](const char* name) {
        const auto i = std::find(rows[0].begin(), rows[0].end(), name);
        REQUIRE(i != rows[0].end());
        return std::size_t(i - rows[0].begin());
    };
    const std::size_t est = col("estimator"), frame = col("frame"), rel = col("relMSE"), flicker = col("flicker"),
                      change = col("reference_change");
    std::map<std::string, std::map<int, std::pair<double, double>>> by;  // estimator -> frame -> (relMSE, flicker)
    for (std::size_t r = 1; r < rows.size(); ++r) {
        by[rows[r][est]][std::stoi(rows[r][frame])] = {std::stod(rows[r][rel]), rows[r][flicker] == "nan" ? NAN : std::stod(rows[r][flicker])};
        if (std::stoi(rows[r][frame]) > 20) CHECK(std::stod(rows[r][change]) == 0.0);
    }
    REQUIRE(by.size() == 2);
    for (int f = 21; f < 24; ++f) {
        const auto& u = by.at("uniform:render.samples=4");
        const double ratio = u.at(f).second / (u.at(f).first + u.at(f - 1).first);
        INFO("uniform frame " << f << ": flicker / (relMSE + previous relMSE) = " << ratio);
        CHECK((ratio > 0.8 && ratio < 1.2));
        const auto& r = by.at("restir:pairwise");
        const double restirRatio = r.at(f).second / (r.at(f).first + r.at(f - 1).first);
        INFO("restir frame " << f << ": " << restirRatio);
        CHECK(restirRatio < 0.8 * ratio);
    }
}

TEST_CASE("bias over crops of the view: each pixel's figures are the whole frame's, restir's with a margin over the whole frame",
          "[cli][experiments][crops]") {
    const auto dir = accretion::test::scratchDir("bias_crops");
    std::string out;
    const std::string scene = tinyScene() + " --quiet --frames 20:21";
    REQUIRE(runCommand(kBin + " render " + scene + " --estimator exact -o " + (dir / "whole.exr").string(), out) == 0);
    // Two crops of the 96x64 frame, rendered alone: the references of a stratified measurement.
    REQUIRE(runCommand(kBin + " render " + scene + " --estimator exact -D render.crop=[8,40,8,32] -o " + (dir / "a.exr").string(), out) == 0);
    REQUIRE(runCommand(kBin + " render " + scene + " --estimator exact -D render.crop=[56,88,30,54] -o " + (dir / "b.exr").string(), out) == 0);
    const std::string common = kBin + " bias " + tinyScene() + " --quiet --frame 20 --seeds 3 --estimators ris,restir:pairwise ";
    REQUIRE(runCommand(common + "--reference " + (dir / "whole.exr").string() + " -o " + (dir / "w").string(), out) == 0);
    // A margin beyond the frame: restir renders the whole frame for each crop.
    const std::string crops = "--reference " + (dir / "a.exr").string() + " --reference " + (dir / "b.exr").string();
    REQUIRE(runCommand(common + crops + " --crop-margin 1000 -o " + (dir / "c").string(), out) == 0);
    INFO(out);
    // The bias maps: the crops' pixels are the whole run's bit for bit (ris
    // renders a crop alone as the whole frame does; restir renders the whole
    // frame here), zero elsewhere.
    for (const char* est : {"ris", "restir_pairwise"}) {
        INFO(est);
        const RgbLayer whole = readExrLayer(dir / fmt::format("w.{}.exr", est), "bias");
        const RgbLayer cropped = readExrLayer(dir / fmt::format("c.{}.exr", est), "bias");
        REQUIRE(cropped.width == 96);
        std::size_t inside = 0, same = 0, zeroOutside = 0, outside = 0;
        for (std::uint32_t y = 0; y < 64; ++y)
            for (std::uint32_t x = 0; x < 96; ++x) {
                const std::size_t p = std::size_t(y) * 96 + x;
                const bool in = (x >= 8 && x < 40 && y >= 8 && y < 32) || (x >= 56 && x < 88 && y >= 30 && y < 54);
                if (in) {
                    ++inside;
                    same += cropped.rgb[p] == whole.rgb[p];
                } else {
                    ++outside;
                    zeroOutside += cropped.rgb[p] == Vec3(0.0f);
                }
            }
        CHECK(inside == 2 * 32 * 24);
        CHECK(same == inside);
        CHECK(zeroOutside == outside);
    }
    const nlohmann::json j = nlohmann::json::parse(readFile(dir / "c.json"));
    CHECK(j["crops"].size() == 2);
    CHECK(j["crop_margin"] == 1000);
    // restir's reuse is counted over the crops' pixels alone (a margin's are
    // not measured): one temporal offer per hit pixel of the crops and seed.
    const std::vector<std::uint32_t> ids = readExrUintChannel(dir / "whole.exr", "particle.id");
    REQUIRE(ids.size() == 96 * 64);
    std::size_t hits = 0;
    for (std::uint32_t y = 0; y < 64; ++y)
        for (std::uint32_t x = 0; x < 96; ++x)
            hits += ((x >= 8 && x < 40 && y >= 8 && y < 32) || (x >= 56 && x < 88 && y >= 30 && y < 54)) && ids[std::size_t(y) * 96 + x] != 0xffffffffu;
    CHECK(hits > 100);
    CHECK(j.at("reuse").at("restir:pairwise").at("temporalResampling").at("offered").get<std::size_t>() == 3 * hits);
    // With the default margin restir renders each crop's window alone: its
    // figures move (another window, other edges) but stay of one estimator.
    REQUIRE(runCommand(common + crops + " -o " + (dir / "m").string(), out) == 0);
    // Overlapping crops and a reference of another size are refused, naming the files.
    CHECK(runCommand(common + crops + " --reference " + (dir / "a.exr").string() + " -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("a.exr") && Contains("overlap"));
    CHECK_FALSE(std::filesystem::exists(dir / "bad.json"));
}

TEST_CASE("bias: relMSE's anatomy sums to it, and the floor of one value a particle is the reference's own", "[cli][experiments][anatomy]") {
    const auto dir = accretion::test::scratchDir("bias_anatomy");
    std::string out;
    REQUIRE(runCommand(kBin + " render " + tinyScene() + " --quiet --estimator exact -o " + (dir / "exact.exr").string(), out) == 0);
    const std::string cmd = kBin + " bias " + tinyScene() + " --quiet --reference " + (dir / "exact.exr").string() +
                            " --frame 0 --estimators exact,uniform,particle_split --seeds 3 -o " + (dir / "b").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(cmd << "\n" << out);
    const auto rows = readCsv(dir / "b.csv");
    REQUIRE(rows.size() == 4);
    const auto col = [&](const char* c) {
        const auto i = std::find(rows[0].begin(), rows[0].end(), c);
        REQUIRE(i != rows[0].end());
        return std::size_t(i - rows[0].begin());
    };
    for (std::size_t r = 1; r < rows.size(); ++r) {
        const double all = std::stod(rows[r][col("rel_mse")]), persistent = std::stod(rows[r][col("rel_mse_persistent")]),
                     noise = std::stod(rows[r][col("rel_mse_noise")]);
        INFO(rows[r][0]);
        CHECK(persistent + noise == Approx(all).epsilon(1e-5).margin(1e-12));
        if (rows[r][0] == "exact") {  // deterministic and the reference itself: neither part
            CHECK(persistent == 0.0);
            CHECK(noise == 0.0);
        } else {
            CHECK(noise > 0.0);
        }
    }
    // The floor, recomputed here from the reference as OpenImageIO reads it.
    auto in = OIIO::ImageInput::open((dir / "exact.exr").string());
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    const int lr = spec.channelindex("Lr.R"), id = spec.channelindex("particle.id");
    REQUIRE((lr >= 0 && id >= 0));
    const std::size_t pixels = std::size_t(spec.width) * spec.height;
    std::vector<float> rgb(pixels * 3);
    std::vector<std::uint32_t> ids(pixels);
    REQUIRE(in->read_image(0, 0, lr, lr + 3, OIIO::TypeDesc::FLOAT, rgb.data()));
    REQUIRE(in->read_image(0, 0, id, id + 1, OIIO::TypeDesc::UINT, ids.data()));
    std::map<std::uint32_t, std::pair<std::array<double, 3>, int>> sums;
    for (std::size_t p = 0; p < pixels; ++p) {
        if (ids[p] == 0xffffffffu) continue;
        auto& [s, n] = sums[ids[p]];
        for (int c = 0; c < 3; ++c) s[c] += rgb[3 * p + c];
        ++n;
    }
    double floor = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        if (ids[p] == 0xffffffffu) continue;
        const auto& [s, n] = sums.at(ids[p]);
        for (int c = 0; c < 3; ++c) {
            const double r = rgb[3 * p + c], d = s[c] / n - r;
            floor += d * d / (r * r + 1e-2);
        }
    }
    floor /= 3.0 * double(pixels);
    const nlohmann::json j = nlohmann::json::parse(readFile(dir / "b.json"));
    CHECK(j.at("particle_mean_floor").at("rel_mse").get<double>() == Approx(floor).epsilon(1e-9));
    CHECK(j.at("particle_mean_floor").at("particles").get<std::size_t>() == sums.size());
    CHECK(floor > 0.0);
    CHECK_THAT(out, Contains("relMSE floor"));
}

TEST_CASE("bias --age-frames: the error by the frames each pixel's particle has been in view", "[cli][experiments][anatomy]") {
    const auto dir = accretion::test::scratchDir("bias_age");
    std::string out;
    const std::string scene = tinyScene() + " --quiet";
    // Frames 19 and 20 with their particle ids, as a user renders them.
    REQUIRE(runCommand(kBin + " render " + scene + " --estimator exact --frames 19:21 -o " + (dir / "f.{frame}.exr").string(), out) == 0);
    const std::string cmd = kBin + " bias " + scene + " --reference " + (dir / "f.0020.exr").string() +
                            " --frame 20 --history 20 --seeds 3 --age-frames 4 --estimators particle_split:particle_split.history=0.8 -o " +
                            (dir / "b").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(cmd << "\n" << out);
    const nlohmann::json j = nlohmann::json::parse(readFile(dir / "b.json"));
    const nlohmann::json& groups = j.at("by_age").at("particle_split:particle_split.history=0.8");
    // No particle; 1; 2-3; 4; more than 4.
    REQUIRE(groups.size() == 5);
    CHECK(groups[1].at("frames_in_view") == "1");
    CHECK(groups[2].at("frames_in_view") == "2-3");
    CHECK(groups[4].at("frames_in_view") == "more than 4");
    // The groups' parts are the row's, and their pixels every pixel measured.
    const nlohmann::json& row = j.at("rows")[0];
    double noise = 0.0, persistent = 0.0;
    std::size_t pixels = 0;
    for (const auto& g : groups) {
        noise += g.at("rel_mse_noise").get<double>();
        persistent += g.at("rel_mse_persistent").get<double>();
        pixels += g.at("pixels").get<std::size_t>();
    }
    CHECK(noise == Approx(row.at("rel_mse_noise").get<double>()).epsilon(1e-9));
    CHECK(persistent == Approx(row.at("rel_mse_persistent").get<double>()).epsilon(1e-9).margin(1e-15));
    const std::vector<std::uint32_t> now = readExrUintChannel(dir / "f.0020.exr", "particle.id");
    const std::vector<std::uint32_t> before = readExrUintChannel(dir / "f.0019.exr", "particle.id");
    REQUIRE(now.size() == before.size());
    CHECK(pixels == now.size());
    // The pixels of group "1" are those whose particle frame 19 does not show,
    // counted here from the two renders' files; those of no particle, the misses.
    const std::set<std::uint32_t> shown(before.begin(), before.end());
    std::size_t fresh = 0, misses = 0;
    for (const std::uint32_t id : now) {
        misses += id == 0xffffffffu;
        fresh += id != 0xffffffffu && !shown.count(id);
    }
    CHECK(groups[0].at("pixels").get<std::size_t>() == misses);
    CHECK(groups[1].at("pixels").get<std::size_t>() == fresh);
    CHECK(fresh > 0);  // the disk turns: particles come into view
    // Frame 2 has 2 frames before it, not 4: one clear error, nothing written.
    CHECK(runCommand(kBin + " bias " + scene + " --reference " + (dir / "f.0020.exr").string() +
                         " --frame 2 --seeds 3 --age-frames 4 --estimators uniform -o " + (dir / "bad").string(), out) != 0);
    CHECK_THAT(out, Contains("--age-frames"));
    CHECK_FALSE(std::filesystem::exists(dir / "bad.json"));
}

namespace {

/// A 4x1 frame as render writes one: Lr.R/G/B (float) and particle.id
/// (uint32), written with OpenImageIO: pixels 0-1 see particle 5 lit `lit`,
/// pixel 2 particle 9 lit 1, pixel 3 none.
void writeLagFrame(const std::filesystem::path& file, float lit, bool withIds = true) {
    OIIO::ImageSpec spec(4, 1, withIds ? 4 : 3, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Lr.R", "Lr.G", "Lr.B"};
    if (withIds) {
        spec.channelnames.push_back("particle.id");
        spec.channelformats = {OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::UINT32};
    }
    std::vector<unsigned char> bytes;
    const auto put = [&](const void* v) { bytes.insert(bytes.end(), (const unsigned char*)v, (const unsigned char*)v + 4); };
    const float light[4] = {lit, lit, 1.0f, 0.0f};
    const std::uint32_t ids[4] = {5, 5, 9, 0xffffffffu};
    for (int p = 0; p < 4; ++p) {
        for (int c = 0; c < 3; ++c) put(&light[p]);
        if (withIds) put(&ids[p]);
    }
    auto out = OIIO::ImageOutput::create(file.string());
    REQUIRE(out);
    REQUIRE(out->open(file.string(), spec));
    REQUIRE(out->write_image(OIIO::TypeDesc::UNKNOWN, bytes.data()));
    REQUIRE(out->close());
}

/// A crop as bias's references are: one black pixel at (x, 0) of a frame `fullWidth` x 1.
void writeLagCrop(const std::filesystem::path& file, int x, int fullWidth) {
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::FLOAT);
    spec.x = x;
    spec.full_width = fullWidth;
    spec.full_height = 1;
    const float rgb[3] = {0.0f, 0.0f, 0.0f};
    auto out = OIIO::ImageOutput::create(file.string());
    REQUIRE(out);
    REQUIRE(out->open(file.string(), spec));
    REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, rgb));
    REQUIRE(out->close());
}

}  // namespace

TEST_CASE("lag: a history's lag on exact frames, in closed form, and none where nothing moves", "[cli][experiments][lag]") {
    const auto dir = accretion::test::scratchDir("lag");
    std::string out;
    SECTION("frames in closed form: particle 5 lit 1, 2, 4; h = 0.5 from its first frame: 1, 1.5, 2.75") {
        const float lit[3] = {1.0f, 2.0f, 4.0f};
        for (int f = 0; f < 3; ++f) writeLagFrame(dir / fmt::format("f.{:04d}.exr", f), lit[f]);
        const std::string cmd = kBin + " lag " + (dir / "f.{frame}.exr").string() +
                                " --frames 0:3 --history 0.5,0 --start first --json -q --csv " + (dir / "trend.csv").string();
        INFO(cmd << "\n" << out);
        REQUIRE(runCommand(cmd, out) == 0);
        const auto rows = nlohmann::json::parse(out.substr(out.find('[')));
        REQUIRE(rows.size() == 2);
        // Pixels 0-1: 2.75 against 4; pixel 2: 1 against 1: (2 x 2.75 + 1) / (2 x 4 + 1) - 1.
        CHECK(rows[0]["energy_pct"].get<double>() == Approx(100.0 * (6.5 / 9.0 - 1.0)));
        CHECK(rows[0]["rel_mse"].get<double>() == Approx(2.0 * 1.25 * 1.25 / (16.0 + kRelMseEpsilon) / 4.0));
        CHECK(rows[0]["particles"].get<int>() == 2);
        CHECK(rows[1]["energy_pct"].get<double>() == 0.0);
        const auto trend = readCsv(dir / "trend.csv");
        REQUIRE(trend.size() == 4);
        CHECK(std::stod(trend[1][1]) == Approx(3.0 / 9.0));  // frame 0: (2 x 1 + 1) / (2 x 4 + 1)
        CHECK(std::stod(trend[3][1]) == 1.0);
        // --subtract frames of particle 5 lit 0.5 (particle 9 lit 1, as here):
        // 0.5, 1.5, 3.5 averaged to 2.25 against 3.5; particle 9 lit 0. The
        // errors stay relative to the whole light (4 and 1 in the last frame).
        for (int f = 0; f < 3; ++f) writeLagFrame(dir / fmt::format("s.{:04d}.exr", f), 0.5f);
        REQUIRE(runCommand(kBin + " lag " + (dir / "f.{frame}.exr").string() + " --frames 0:3 --history 0.5 --start first --json -q "
                               "--subtract " + (dir / "s.{frame}.exr").string(), out) == 0);
        const auto less = nlohmann::json::parse(out.substr(out.find('[')))[0];
        // --windows-of a crop holding pixel 1 alone (its data window in the 4x1 frame): 2.75 against 4.
        writeLagCrop(dir / "crop.exr", 1, 4);
        std::string cropped;
        REQUIRE(runCommand(kBin + " lag " + (dir / "f.{frame}.exr").string() + " --frames 0:3 --history 0.5 --start first --json -q "
                               "--windows-of " + (dir / "crop.exr").string(), cropped) == 0);
        CHECK(nlohmann::json::parse(cropped.substr(cropped.find('[')))[0]["energy_pct"].get<double>() == Approx(100.0 * (2.75 / 4.0 - 1.0)));
        CHECK(less["energy_pct"].get<double>() == Approx(100.0 * (2.0 * 2.25 - 2.0 * 3.5) / 9.0));
        CHECK(less["rel_mse"].get<double>() == Approx(2.0 * 1.25 * 1.25 / (16.0 + kRelMseEpsilon) / 4.0));
    }
    SECTION("bad frames: one error naming the file, exit 1") {
        writeLagFrame(dir / "g.0000.exr", 1.0f);
        writeLagFrame(dir / "g.0001.exr", 1.0f, false);
        CHECK(runCommand(kBin + " lag " + (dir / "g.{frame}.exr").string() + " --frames 0:2 -q", out) == 1);
        CHECK_THAT(out, Contains("g.0001.exr: no particle.id channel"));
        CHECK(runCommand(kBin + " lag " + (dir / "g.{frame}.exr").string() + " --frames 0:3 -q", out) == 1);
        CHECK_THAT(out, Contains("g.0002.exr: not found (frame 2 of --frames 0:3)"));
        CHECK(runCommand(kBin + " lag " + (dir / "g.{frame}.exr").string() + " --frames 0:1 -q --csv " + (dir / "g.0000.exr").string(),
                         out) == 1);
        CHECK(runCommand(kBin + " lag " + (dir / "g.{frame}.exr").string() + " --frames 0:1 --history 1 -q", out) == 1);
        writeLagCrop(dir / "wide.exr", 6, 8);  // a crop of an 8x1 frame
        CHECK(runCommand(kBin + " lag " + (dir / "g.{frame}.exr").string() + " --frames 0:1 -q --windows-of " + (dir / "wide.exr").string(),
                         out) == 1);
        CHECK_THAT(out, Contains("wide.exr: its window (1x1 at (6, 0) of 8x1) is not one of the 4x1 frames'"));
    }
    SECTION("render's exact frames: a disk held still has none, a moving one some") {
        for (const std::string gm : {"0", "40"}) {
            const std::string pattern = (dir / ("gm" + gm + ".{frame}.exr")).string();
            REQUIRE(runCommand(kBin + " render " + tinyScene() + " -D particles.gm=" + gm + " --frames 20:24 --quiet --estimator exact -o " +
                                   pattern, out) == 0);
            const std::string cmd = kBin + " lag " + pattern + " --frames 20:24 --history 0.9 --json -q";
            INFO(cmd << "\n" << out);
            REQUIRE(runCommand(cmd, out) == 0);
            const auto rows = nlohmann::json::parse(out.substr(out.find('[')));
            if (gm == "0") {
                CHECK(rows[0]["energy_pct"].get<double>() == 0.0);
                CHECK(rows[0]["rel_mse"].get<double>() == 0.0);
            } else {
                CHECK(rows[0]["rel_mse"].get<double>() > 1e-6);
            }
        }
    }
}
