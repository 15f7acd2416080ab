// The renderer's EXR layer (OpenEXR) against OpenImageIO: what one writes the
// other reads, windows, channel types and attributes included.
#include <catch2/catch.hpp>

#include <bit>
#include <fstream>

#include <OpenImageIO/imageio.h>

#include "accretion/core/error.h"
#include "accretion/io/exr_file.h"
#include "support/test_scenes.h"

using namespace accretion;
namespace OIIO = OIIO_NAMESPACE;

TEST_CASE("EXR files: a window of uint and float channels with attributes, written and read both ways", "[io][exr]") {
    const auto dir = accretion::test::scratchDir("exr_file");
    // A 5x3 data window at (2, 1) of a 9x6 image: "a" float, "b.id" uint.
    std::vector<std::uint32_t> bits;
    for (std::uint32_t p = 0; p < 15; ++p) {
        bits.push_back(std::bit_cast<std::uint32_t>(0.25f * float(p) - 1.0f));
        bits.push_back(0xfffffff0u + p);
    }
    ExrImage img;
    img.fullWidth = 9;
    img.fullHeight = 6;
    img.x0 = 2;
    img.y0 = 1;
    img.width = 5;
    img.height = 3;
    img.channels = {"a", "b.id"};
    img.uints = {false, true};
    img.bits = bits.data();
    img.strings = {{"accretion:seed", "42"}};
    img.floats = {{"worldToCamera", {"m44f", {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}}},
                  {"accretion:jitter", {"v2f", {0.25f, -0.5f}}}};
    const auto file = dir / "w.exr";
    writeExr(file, img);

    // OpenImageIO reads what was written.
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    CHECK(spec.x == 2);
    CHECK(spec.y == 1);
    CHECK(spec.width == 5);
    CHECK(spec.height == 3);
    CHECK(spec.full_width == 9);
    CHECK(spec.full_height == 6);
    CHECK(spec.get_string_attribute("compression") == "zip");
    CHECK(spec.get_string_attribute("accretion:seed") == "42");
    const OIIO::ParamValue* m = spec.find_attribute("worldToCamera");
    REQUIRE(m != nullptr);
    CHECK(m->type() == OIIO::TypeMatrix44);
    CHECK(static_cast<const float*>(m->data())[6] == 7.0f);
    const OIIO::ParamValue* j = spec.find_attribute("accretion:jitter");
    REQUIRE(j != nullptr);
    CHECK(static_cast<const float*>(j->data())[1] == -0.5f);
    REQUIRE(spec.nchannels == 2);
    const int a = spec.channelindex("a"), b = spec.channelindex("b.id");
    REQUIRE((a >= 0 && b >= 0));
    CHECK(spec.channelformat(b) == OIIO::TypeDesc::UINT);
    std::vector<std::uint32_t> back(30);
    REQUIRE(in->read_image(0, 0, 0, 2, OIIO::TypeDesc::UNKNOWN, back.data()));
    for (std::size_t p = 0; p < 15; ++p) {
        CHECK(back[p * 2 + std::size_t(a)] == bits[p * 2]);
        CHECK(back[p * 2 + std::size_t(b)] == bits[p * 2 + 1]);
    }

    // And this layer reads it back: the header, native bits, floats by value.
    ExrReader reader(file);
    const ExrHeader& h = reader.header();
    CHECK((h.fullWidth == 9 && h.fullHeight == 6 && h.x0 == 2 && h.y0 == 1 && h.width == 5 && h.height == 3));
    CHECK(h.channels == std::vector<std::string>{"a", "b.id"});
    CHECK(h.strings.at("accretion:seed") == "42");
    CHECK(h.floats.at("worldToCamera") == img.floats.at("worldToCamera"));
    CHECK(h.printed.at("accretion:jitter") == "0.25 -0.5");
    CHECK(reader.pixels({"a", "b.id"}, false) == bits);
    const std::vector<std::uint32_t> asFloat = reader.pixels({"b.id"}, true);
    CHECK(std::bit_cast<float>(asFloat[3]) == float(0xfffffff0u + 3));
}

TEST_CASE("EXR files: half channels are read as floats and refused as 32-bit bits, other files are refused by name", "[io][exr]") {
    const auto dir = accretion::test::scratchDir("exr_file_half");
    const auto file = dir / "half.exr";
    {
        // An engine's frame: RGB halves, written by OpenImageIO.
        OIIO::ImageSpec spec(4, 2, 3, OIIO::TypeDesc::HALF);
        auto out = OIIO::ImageOutput::create("openexr");
        REQUIRE(out);
        std::vector<float> px(24);
        for (std::size_t i = 0; i < px.size(); ++i) px[i] = 0.5f * float(i);
        REQUIRE(out->open(file.string(), spec));
        REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
        REQUIRE(out->close());
    }
    ExrReader reader(file);
    const ExrHeader& h = reader.header();
    REQUIRE(h.types.size() == 3);
    CHECK(h.types[0] == ExrChannelType::half);
    const std::vector<std::uint32_t> g = reader.pixels({"G"}, true);
    REQUIRE(g.size() == 8);
    for (std::size_t p = 0; p < 8; ++p) CHECK(std::bit_cast<float>(g[p]) == 0.5f * float(p * 3 + 1));
    CHECK_THROWS_WITH(reader.pixels({"G"}, false), Catch::Contains("half.exr: channel G is not 32-bit"));
    CHECK_THROWS_WITH(reader.pixels({"Z"}, true), Catch::Contains("half.exr: no channel Z"));

    const auto text = dir / "not.exr";
    std::ofstream(text) << "not an image";
    CHECK_THROWS_AS(readExrHeader(text), InputError);
    CHECK_THROWS_WITH(readExrHeader(text), Catch::Contains("not.exr: cannot read EXR"));
}
