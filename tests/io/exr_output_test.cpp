#include <catch2/catch.hpp>

#include <OpenImageIO/imageio.h>

#include "accretion/io/exr_output.h"
#include "support/test_scenes.h"

using namespace accretion;
namespace OIIO = OIIO_NAMESPACE;

TEST_CASE("EXR: layers, formats, values and metadata read back with OpenImageIO", "[io][exr]") {
    const auto dir = accretion::test::scratchDir("exr");
    Settings s = accretion::test::smallDiskSettings();
    s.render.estimator = EstimatorKind::power;
    s.render.samples = 4;
    const FrameImage img = accretion::test::renderParticles(s, ParticleSource(s).frame(0));

    const auto file = dir / "frame.exr";
    writeFrameExr(file, img, true, {{"seed", "42"}, {"estimator", "power"}});
    REQUIRE(std::filesystem::exists(file));
    for (const auto& e : std::filesystem::directory_iterator(dir)) REQUIRE(e.path().filename() == "frame.exr");  // no temp left

    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    REQUIRE(spec.width == int(s.camera.width));
    REQUIRE(spec.height == int(s.camera.height));
    REQUIRE(spec.get_string_attribute("compression") == "zip");
    REQUIRE(spec.get_string_attribute("accretion:seed") == "42");
    REQUIRE(spec.get_string_attribute("accretion:estimator") == "power");

    const std::vector<std::string> expected = {"R", "G", "B", "Le.R", "Le.G", "Le.B", "Lr.R", "Lr.G", "Lr.B", "depth.Z",
                                               "N.X", "N.Y", "N.Z", "particle.id", "rejected", "Lr_stderr.R", "Lr_stderr.G",
                                               "Lr_stderr.B", "spp"};
    REQUIRE(spec.nchannels == int(expected.size()));
    auto channel = [&](const std::string& name) {
        for (int c = 0; c < spec.nchannels; ++c)
            if (spec.channelnames[c] == name) return c;
        FAIL("missing channel " << name);
        return -1;
    };
    for (const auto& name : expected) {
        const int c = channel(name);
        const OIIO::TypeDesc t = spec.channelformats.empty() ? spec.format : spec.channelformats[c];
        REQUIRE(t == (name == "particle.id" ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT));
    }
    std::vector<float> px(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
    std::vector<std::uint32_t> ids(std::size_t(spec.width) * spec.height);
    const int idc = channel("particle.id");
    REQUIRE(in->read_image(0, 0, idc, idc + 1, OIIO::TypeDesc::UINT, ids.data()));
    int hits = 0;
    for (std::size_t i = 0; i < ids.size(); ++i) {
        const float* v = &px[i * spec.nchannels];
        REQUIRE(ids[i] == img.particle[i]);
        REQUIRE(v[channel("R")] == img.L[i].x);
        REQUIRE(v[channel("Lr.G")] == img.lighting.Lr[i].y);
        REQUIRE(v[channel("Le.B")] == img.Le[i].z);
        REQUIRE(v[channel("Lr_stderr.R")] == img.lighting.Lr_stderr[i].x);
        REQUIRE(v[channel("depth.Z")] == img.depth[i]);
        REQUIRE(v[channel("N.Y")] == img.normal[i].y);
        REQUIRE(v[channel("spp")] == img.lighting.spp[i]);
        REQUIRE(v[channel("rejected")] == img.lighting.rejected[i]);
        hits += ids[i] != kNoParticle;
    }
    REQUIRE(hits > 10);
}
