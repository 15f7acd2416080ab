// The renderer's PNG writer (libpng) read back with OpenImageIO.
#include <catch2/catch.hpp>

#include <OpenImageIO/imageio.h>

#include "accretion/io/png_file.h"
#include "support/test_scenes.h"

using namespace accretion;
namespace OIIO = OIIO_NAMESPACE;

TEST_CASE("PNG files: 8-bit RGB pixels and the Description text read back with OpenImageIO", "[io][png]") {
    const auto dir = accretion::test::scratchDir("png_file");
    const std::uint32_t w = 7, h = 5;
    std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
    for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = std::uint8_t((i * 37u + 11u) % 256u);
    const auto file = dir / "p.png";
    writePng(file, rgb, w, h, "Lr: scale [0, 1]");
    for (const auto& e : std::filesystem::directory_iterator(dir)) CHECK(e.path().filename() == "p.png");  // no temporary left

    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const OIIO::ImageSpec& spec = in->spec();
    CHECK(spec.width == int(w));
    CHECK(spec.height == int(h));
    REQUIRE(spec.nchannels == 3);
    CHECK(spec.format == OIIO::TypeDesc::UINT8);
    CHECK(spec.get_string_attribute("ImageDescription") == "Lr: scale [0, 1]");
    std::vector<std::uint8_t> back(rgb.size());
    REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, back.data()));
    CHECK(back == rgb);
}
