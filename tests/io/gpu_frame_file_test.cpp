// The twin's frame file: a round trip, refusal of damaged files, and
// import-gpu's EXR read back with OpenImageIO.
#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "accretion/core/error.h"
#include "accretion/io/gpu_frame_file.h"
#include "support/cli.h"
#include "support/test_scenes.h"

using namespace accretion;
using namespace accretion::test;

namespace {

GpuFrame sampleFrame() {
    GpuFrame f;
    f.width = 5;
    f.height = 3;
    f.frame = 7;
    f.camera = CameraPose::lookAt(DVec3(1, 2, 3), DVec3(0, 0, 0), DVec3(0, 1, 0), 40.0);
    f.camera.jitterX = 0.25;
    f.metadata = {{"renderer", "accretion-optix"}, {"frame", "7"}, {"estimator", "exact"}};
    for (std::uint32_t k = 0; k < 15; ++k) {
        const float v = 0.5f * float(k) + 0.125f;
        f.Lr.push_back(Vec3(v, 2.0f * v, 3.0f * v));
        f.Le.push_back(Vec3(k % 3 ? 1.0f : 0.0f));
        f.L.push_back(f.Le.back() + f.Lr.back());
        f.normal.push_back(Vec3(0.0f, 0.0f, 1.0f));
        f.depth.push_back(float(k));
        f.particle.push_back(k == 4 ? 0xffffffffu : 100u + k);
    }
    return f;
}

/// An EXR as OpenImageIO reads it: its spec and every channel as float.
std::pair<OIIO::ImageSpec, std::vector<float>> readImage(const std::filesystem::path& file) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    OIIO::ImageSpec spec = in->spec();
    std::vector<float> px(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    return {spec, px};
}

}  // namespace

TEST_CASE("a GPU frame file reads back bit for bit, and damaged files are refused", "[io][gpu]") {
    const auto dir = scratchDir("gpu_frame");
    const GpuFrame f = sampleFrame();
    writeGpuFrame(dir / "f.gpuframe", f);
    const GpuFrame g = readGpuFrame(dir / "f.gpuframe");
    CHECK(g.width == 5);
    CHECK(g.height == 3);
    CHECK(g.frame == 7);
    CHECK(g.camera.eye == f.camera.eye);
    CHECK(g.camera.forward == f.camera.forward);
    CHECK(g.camera.jitterX == 0.25);
    CHECK(g.metadata == f.metadata);
    CHECK(g.L == f.L);
    CHECK(g.Le == f.Le);
    CHECK(g.Lr == f.Lr);
    CHECK(g.normal == f.normal);
    CHECK(g.depth == f.depth);
    CHECK(g.particle == f.particle);

    // Cut short by one byte, or one byte too long: refused, naming the file.
    const auto size = std::filesystem::file_size(dir / "f.gpuframe");
    std::filesystem::copy_file(dir / "f.gpuframe", dir / "short.gpuframe");
    std::filesystem::resize_file(dir / "short.gpuframe", size - 1);
    CHECK_THROWS_WITH(readGpuFrame(dir / "short.gpuframe"), Catch::Contains("short.gpuframe: the header's 5x3 planes (L, Le, Lr, normal, depth, particle) take 840 bytes, the file holds 839"));
    std::filesystem::copy_file(dir / "f.gpuframe", dir / "long.gpuframe");
    std::ofstream(dir / "long.gpuframe", std::ios::app) << 'x';
    CHECK_THROWS_WITH(readGpuFrame(dir / "long.gpuframe"), Catch::Contains("take 840 bytes, the file holds 841"));
}

TEST_CASE("import-gpu writes render's EXR layers of a GPU frame", "[io][gpu][cli]") {
    const auto dir = scratchDir("gpu_import");
    const GpuFrame f = sampleFrame();
    writeGpuFrame(dir / "g.gpuframe", f);
    std::string out;
    REQUIRE(runCommand(kBin + " import-gpu " + (dir / "g.gpuframe").string(), out) == 0);
    INFO(out);
    const auto [spec, px] = readImage(dir / "g.exr");
    CHECK(spec.width == 5);
    CHECK(spec.height == 3);
    CHECK(spec.get_string_attribute("accretion:renderer") == "accretion-optix");
    CHECK(spec.get_string_attribute("accretion:frame") == "7");
    const int lr = spec.channelindex("Lr.R"), lb = spec.channelindex("Lr.B"), r = spec.channelindex("R");
    REQUIRE(lr >= 0);
    REQUIRE(lb >= 0);
    REQUIRE(r >= 0);
    for (std::size_t k = 0; k < 15; ++k) {
        CHECK(px[k * spec.nchannels + lr] == f.Lr[k].x);
        CHECK(px[k * spec.nchannels + lb] == f.Lr[k].z);
        CHECK(px[k * spec.nchannels + r] == f.L[k].x);
    }
    CHECK(std::filesystem::exists(dir / "g.png"));
    CHECK(std::filesystem::exists(dir / "g.Lr.png"));
}

TEST_CASE("a GPU frame of Lr alone reads back, and says it is incomplete", "[io][gpu]") {
    const auto dir = scratchDir("gpu_frame_lr");
    GpuFrame f = sampleFrame();
    f.L.clear();
    f.Le.clear();
    f.normal.clear();
    f.depth.clear();
    f.particle.clear();
    writeGpuFrame(dir / "lr.gpuframe", f);
    CHECK(std::filesystem::file_size(dir / "lr.gpuframe") < 15 * sizeof(Vec3) + 1024);
    const GpuFrame g = readGpuFrame(dir / "lr.gpuframe");
    CHECK(g.Lr == f.Lr);
    CHECK(g.L.empty());
    CHECK(g.particle.empty());
    CHECK_FALSE(g.complete());
    CHECK(sampleFrame().complete());
}

TEST_CASE("a Monte Carlo GPU frame keeps its standard error, spp and rejections through import-gpu", "[io][gpu][cli]") {
    const auto dir = scratchDir("gpu_frame_mc");
    GpuFrame f = sampleFrame();
    f.metadata["estimator"] = "power";
    for (std::uint32_t k = 0; k < 15; ++k) {
        f.Lr_stderr.push_back(Vec3(0.01f * float(k), 0.02f, 0.03f));
        f.spp.push_back(float(16 + 8 * (k % 4)));
        f.rejected.push_back(float(k % 5 == 0));
    }
    writeGpuFrame(dir / "mc.gpuframe", f);
    const GpuFrame g = readGpuFrame(dir / "mc.gpuframe");
    CHECK(g.Lr_stderr == f.Lr_stderr);
    CHECK(g.spp == f.spp);
    CHECK(g.rejected == f.rejected);
    CHECK(g.complete());

    std::string out;
    REQUIRE(runCommand(kBin + " import-gpu " + (dir / "mc.gpuframe").string(), out) == 0);
    INFO(out);
    const auto [spec, px] = readImage(dir / "mc.exr");
    const int se = spec.channelindex("Lr_stderr.R"), spp = spec.channelindex("spp"), rej = spec.channelindex("rejected");
    REQUIRE(se >= 0);
    REQUIRE(spp >= 0);
    REQUIRE(rej >= 0);
    for (std::size_t k = 0; k < 15; ++k) {
        CHECK(px[k * spec.nchannels + se] == f.Lr_stderr[k].x);
        CHECK(px[k * spec.nchannels + spp] == f.spp[k]);
        CHECK(px[k * spec.nchannels + rej] == f.rejected[k]);
    }
}

TEST_CASE("a GPU frame's planes are read in the order its header lists them", "[io][gpu]") {
    // An engine that writes Lr first and lists it first: its Lr is Lr, not L.
    const auto dir = scratchDir("gpu_frame_order");
    const GpuFrame f = sampleFrame();
    writeGpuFrame(dir / "f.gpuframe", f);
    std::ifstream in(dir / "f.gpuframe", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::uint64_t length = 0;
    std::memcpy(&length, bytes.data() + 8, 8);
    nlohmann::json header = nlohmann::json::parse(bytes.substr(16, length));
    REQUIRE(header["planes"] == nlohmann::json({"L", "Le", "Lr", "normal", "depth", "particle"}));
    header["planes"] = {"Lr", "L", "Le", "normal", "depth", "particle"};
    const std::string text = header.dump();
    const std::uint64_t newLength = text.size();
    const std::size_t planes = 16 + length, rgb = 15 * 12;  // L, Le, Lr: 15 pixels of 3 floats each
    std::string reordered = bytes.substr(0, 8) + std::string(reinterpret_cast<const char*>(&newLength), 8) + text +
                            bytes.substr(planes + 2 * rgb, rgb) + bytes.substr(planes, 2 * rgb) + bytes.substr(planes + 3 * rgb);
    std::ofstream(dir / "lr_first.gpuframe", std::ios::binary) << reordered;
    const GpuFrame g = readGpuFrame(dir / "lr_first.gpuframe");
    CHECK(g.Lr == f.Lr);
    CHECK(g.L == f.L);
    CHECK(g.Le == f.Le);
    CHECK(g.normal == f.normal);
    CHECK(g.particle == f.particle);
}
