// split at a resolution whose near lights the old per-frame cache could not
// hold (256x256 at k = 1024 needed 269 MB of 256 MiB; here 1000 particles): band-major sweeps
// keep nothing between sweeps, and the estimator stays the sum it must be.
// Checked against exact (itself checked against the brute-force oracle),
// read back with OpenImageIO.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

#include <OpenImageIO/imageio.h>

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
