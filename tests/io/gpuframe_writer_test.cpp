// The standalone reference writer an engine copies
// (include/accretion/engine/gpuframe_writer.h) writes what accretion's reader
// reads: every plane bit for bit, the camera and metadata exactly.
#include <catch2/catch.hpp>

#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "accretion/engine/gpuframe_writer.h"
#include "accretion/io/gpu_frame_file.h"
#include "support/test_scenes.h"

namespace {

template <class T, class U>
bool sameBits(const std::vector<T>& a, const std::vector<U>& b) {
    return a.size() * sizeof(T) == b.size() * sizeof(U) && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

}  // namespace

TEST_CASE("the engine's reference .gpuframe writer writes what accretion reads, bit for bit", "[io][gpu_frame]") {
    const auto dir = accretion::test::scratchDir("gpuframe_writer");
    accretion_engine::GpuFrameOut f;
    f.width = 7;
    f.height = 3;
    f.frame = 12;
    const double eye[3] = {1.5, 7.0, 17.25}, fwd[3] = {0.0, -0.6, -0.8}, up[3] = {0.0, 0.8, -0.6};
    std::memcpy(f.eye, eye, sizeof eye);
    std::memcpy(f.forward, fwd, sizeof fwd);
    std::memcpy(f.up, up, sizeof up);
    f.tanHalfFov = 0.3249196962329063;
    f.jitter[0] = 0.25;
    f.jitter[1] = -0.125;
    f.metadata = {{"frame", "12"}, {"seed", "3"}, {"estimator", "restir"}, {"device", "a \"quoted\" GPU\twith tab"}};
    const std::size_t n = 21;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1e3f, 1e3f);
    for (auto* plane : {&f.L, &f.Le, &f.Lr, &f.normal, &f.Lr_stderr})
        for (std::size_t k = 0; k < 3 * n; ++k) plane->push_back(u(rng));
    for (auto* plane : {&f.depth, &f.spp, &f.rejected})
        for (std::size_t k = 0; k < n; ++k) plane->push_back(u(rng));
    for (std::size_t k = 0; k < n; ++k) f.particle.push_back(k % 5 == 0 ? 0xffffffffu : std::uint32_t(rng()));
    const auto file = (dir / "engine.gpuframe").string();
    REQUIRE(accretion_engine::writeGpuFrame(file, f));

    const accretion::GpuFrame g = accretion::readGpuFrame(file);
    CHECK(g.width == 7);
    CHECK(g.height == 3);
    CHECK(g.frame == 12);
    CHECK(g.metadata == f.metadata);
    CHECK(g.camera.eye == accretion::DVec3(1.5, 7.0, 17.25));
    CHECK(g.camera.forward == accretion::DVec3(0.0, -0.6, -0.8));
    CHECK(g.camera.tanHalfFov == f.tanHalfFov);
    CHECK(g.camera.jitterX == 0.25);
    CHECK(g.camera.jitterY == -0.125);
    CHECK(sameBits(g.L, f.L));
    CHECK(sameBits(g.Le, f.Le));
    CHECK(sameBits(g.Lr, f.Lr));
    CHECK(sameBits(g.normal, f.normal));
    CHECK(sameBits(g.Lr_stderr, f.Lr_stderr));
    CHECK(sameBits(g.depth, f.depth));
    CHECK(sameBits(g.spp, f.spp));
    CHECK(sameBits(g.rejected, f.rejected));
    CHECK(sameBits(g.particle, f.particle));

    // Lr alone (a frame for bias --gpu-frames); a plane of the wrong size is refused, nothing written.
    accretion_engine::GpuFrameOut lr;
    lr.width = 7;
    lr.height = 3;
    lr.Lr = f.Lr;
    REQUIRE(accretion_engine::writeGpuFrame((dir / "lr.gpuframe").string(), lr));
    CHECK(sameBits(accretion::readGpuFrame(dir / "lr.gpuframe").Lr, f.Lr));
    lr.depth.assign(5, 0.0f);
    CHECK_FALSE(accretion_engine::writeGpuFrame((dir / "bad.gpuframe").string(), lr));
    CHECK_FALSE(std::filesystem::exists(dir / "bad.gpuframe"));
}

TEST_CASE("the engine's .gpuframe writer writes the same header under a decimal-comma locale", "[io][gpu_frame]") {
    // An engine that calls setlocale(LC_ALL, "") on a German desktop: printf
    // writes 0,25 there, which is not JSON. The locale is compiled here from
    // glibc's sources (the `locales` package), so no system locale is needed.
    const auto dir = accretion::test::scratchDir("gpuframe_writer_locale");
    std::string out;
    REQUIRE(accretion::test::runCommand("localedef -i de_DE -f UTF-8 " + (dir / "de_DE.UTF-8").string(), out) == 0);
    accretion_engine::GpuFrameOut f;
    f.width = 2;
    f.height = 1;
    f.frame = 3;
    f.tanHalfFov = 0.3249196962329063;
    f.jitter[0] = 0.25;
    f.jitter[1] = -0.125;
    const double eye[3] = {1.5, 7.0, 17.25};
    std::memcpy(f.eye, eye, sizeof eye);
    f.Lr = {0.5f, 1.5f, 2.5f, 3.5f, 4.5f, 5.5f};
    const auto file = (dir / "comma.gpuframe").string();
    ::setenv("LOCPATH", dir.c_str(), 1);
    const bool german = std::setlocale(LC_ALL, "de_DE.UTF-8") != nullptr;
    char probe[16];
    std::snprintf(probe, sizeof probe, "%.2f", 0.5);
    const bool written = german && accretion_engine::writeGpuFrame(file, f);
    std::setlocale(LC_ALL, "C");
    ::unsetenv("LOCPATH");
    REQUIRE(german);
    CHECK(std::string(probe) == "0,50");  // the locale was in force while the frame was written
    REQUIRE(written);
    const accretion::GpuFrame g = accretion::readGpuFrame(file);
    CHECK(g.camera.tanHalfFov == f.tanHalfFov);
    CHECK(g.camera.jitterX == 0.25);
    CHECK(g.camera.jitterY == -0.125);
    CHECK(g.camera.eye == accretion::DVec3(1.5, 7.0, 17.25));
    CHECK(sameBits(g.Lr, f.Lr));
    // A camera that is not finite has no JSON form: refused, nothing written.
    f.tanHalfFov = std::nan("");
    CHECK_FALSE(accretion_engine::writeGpuFrame((dir / "nan.gpuframe").string(), f));
    CHECK_FALSE(std::filesystem::exists(dir / "nan.gpuframe"));
}
