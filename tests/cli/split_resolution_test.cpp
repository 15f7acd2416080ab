// split at a resolution whose near lights the old per-frame cache could not
// hold (256x256 at k = 1024 needed 269 MB of 256 MiB; here 1000 particles): band-major sweeps
// keep nothing between sweeps, and the estimator stays the sum it must be.
// Checked against exact (itself checked against the brute-force oracle),
// read back with OpenImageIO. And the pilot that picks k: its variance per
// sample against the one renders of its view measure.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <map>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "support/cli.h"

namespace {

using namespace accretion::test;

/// The named channels of an EXR, pixel-interleaved.
std::vector<float> exrChannels(const std::filesystem::path& file, const std::vector<std::string>& names) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const auto& spec = in->spec();
    std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()));
    std::vector<float> out;
    const std::size_t pixels = std::size_t(spec.width) * spec.height;
    std::vector<int> index;
    for (const std::string& n : names) {
        index.push_back(spec.channelindex(n));
        REQUIRE(index.back() >= 0);
    }
    for (std::size_t p = 0; p < pixels; ++p)
        for (const int c : index) out.push_back(all[p * std::size_t(spec.nchannels) + std::size_t(c)]);
    return out;
}

}  // namespace

TEST_CASE("split at a resolution the old near-field cache overflowed: exact when k >= N - 1, unbiased below",
          "[cli][split]") {
    const auto dir = scratchDir("split_resolution");
    const std::string scene = kBin + " render " + kScenes + "/quickstart.toml --quiet -D particles.count=1000 "
                              "-D camera.width=256 -D camera.height=256 --frames 0 ";
    std::string out;
    REQUIRE(runCommand(scene + "--estimator exact -o " + (dir / "exact.exr").string(), out) == 0);
    // k = 1024 >= N - 1: every light is near, the far field is empty: exact, summed in tree order.
    REQUIRE(runCommand(scene + "--estimator split --spp 8 -D render.near_lights=1024 -o " + (dir / "all.exr").string(), out) == 0);
    // k = 16: most light is far, sampled.
    REQUIRE(runCommand(scene + "--estimator split --spp 64 -D render.near_lights=16 -o " + (dir / "some.exr").string(), out) == 0);
    const std::vector<std::string> rgb = {"Lr.R", "Lr.G", "Lr.B"}, sd = {"Lr_stderr.R", "Lr_stderr.G", "Lr_stderr.B"};
    const auto exact = exrChannels(dir / "exact.exr", rgb), all = exrChannels(dir / "all.exr", rgb);
    const auto some = exrChannels(dir / "some.exr", rgb), someSd = exrChannels(dir / "some.exr", sd);
    REQUIRE(exact.size() == std::size_t(256 * 256 * 3));
    double worst = 0.0, sumExact = 0.0, sumSome = 0.0, var = 0.0;
    std::size_t lit = 0;
    for (std::size_t i = 0; i < exact.size(); ++i) {
        worst = std::max(worst, std::fabs(double(all[i]) - exact[i]) / (std::fabs(double(exact[i])) + 1e-12));
        if (i % 3 != 0) continue;  // the z test on red alone: a pixel's channels share their samples
        sumExact += exact[i];
        sumSome += some[i];
        var += double(someSd[i]) * someSd[i];  // pixels are independent (a stream per pixel)
        lit += exact[i] > 0.0f;
    }
    INFO("lit pixels " << lit << ", exact red sum " << sumExact << ", split (k = 16) sum " << sumSome << " +- " << std::sqrt(var));
    REQUIRE(lit > 1000);  // the disk covers enough of the image to measure
    CHECK(worst < 1e-5);  // float summation order alone
    // The image sums: |z| < 4.4 (two-sided 1e-5: this test fails by chance once in 100,000 runs).
    CHECK(std::fabs(sumSome - sumExact) < 4.4 * std::sqrt(var));
    CHECK(std::sqrt(var) < 0.01 * sumExact);  // and the check has power: the error bar is under 1% of the sum
}

TEST_CASE("split's pilot predicts the variance per sample that a render of its view measures", "[cli][split]") {
    // The pilot's V(k) (64 far samples at up to 256 pixels of a 64-pixel-wide
    // view) against the mean over the lit pixels of S x stderr^2 / (Lr^2 +
    // 1e-2) of renders of that same view at fixed k, S = 256 (the render's
    // own standard errors: independent samples on other streams).
    const auto dir = scratchDir("split_pilot_variance");
    const std::string scene = kBin + " render " + kScenes + "/quickstart.toml --quiet -D camera.width=64 -D camera.height=36 "
                              "--frames 0 --estimator split --spp 256 ";
    std::string out;
    REQUIRE(runCommand(scene + "-o " + (dir / "auto.exr").string(), out) == 0);
    const nlohmann::json pilot = nlohmann::json::parse(readFile(dir / "auto.stats.json"))["frames"][0]["near_light_pilot"];
    std::map<std::uint32_t, double> predicted;
    for (const auto& c : pilot["candidates"]) predicted[c["k"].get<std::uint32_t>()] = c["rel_variance"].get<double>();
    std::map<std::uint32_t, double> measured;
    for (const std::uint32_t k : {16u, 1024u}) {
        const auto file = dir / ("k" + std::to_string(k) + ".exr");
        REQUIRE(runCommand(scene + "-D render.near_lights=" + std::to_string(k) + " -o " + file.string(), out) == 0);
        const auto lr = exrChannels(file, {"Lr.R", "Lr.G", "Lr.B"}), sd = exrChannels(file, {"Lr_stderr.R", "Lr_stderr.G", "Lr_stderr.B"});
        double v = 0.0;
        std::size_t lit = 0;
        for (std::size_t p = 0; p + 2 < lr.size(); p += 3) {
            if (lr[p] + lr[p + 1] + lr[p + 2] <= 0.0f) continue;
            ++lit;
            for (int c = 0; c < 3; ++c) v += 256.0 * double(sd[p + c]) * sd[p + c] / (double(lr[p + c]) * lr[p + c] + 1e-2) / 3.0;
        }
        REQUIRE(lit > 200);
        measured[k] = v / double(lit);
        INFO("k = " << k << ": pilot " << predicted[k] << ", render " << measured[k]);
        REQUIRE(predicted.count(k));
        // Heavy-tailed 1/d^2 terms: within a factor 2 (measured: within 25%).
        CHECK(predicted[k] > 0.5 * measured[k]);
        CHECK(predicted[k] < 2.0 * measured[k]);
    }
    // And the order that decides k: a near field of 1024 leaves far less to sample than one of 16.
    CHECK(measured[1024] < 0.2 * measured[16]);
    CHECK(predicted[1024] < 0.2 * predicted[16]);
}
