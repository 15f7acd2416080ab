#include <catch2/catch.hpp>

#include "accretion/core/error.h"
#include "accretion/lighting/reservoir_codec.h"

using namespace accretion;

TEST_CASE("light index bits needed for N lights", "[reservoir][codec]") {
    CHECK(ReservoirCodec::bitsFor(1) == 1);
    CHECK(ReservoirCodec::bitsFor(2) == 1);
    CHECK(ReservoirCodec::bitsFor(65536) == 16);
    CHECK(ReservoirCodec::bitsFor(65537) == 17);
    CHECK(ReservoirCodec::bitsFor(100000) == 17);  // docs/MODEL.md: 100K particles need 17 bits, not 16
}

TEST_CASE("a packed layout that cannot address every particle is rejected with the bits it needs", "[reservoir][codec]") {
    RestirSettings s;
    s.layout = ReservoirLayout::packed;
    s.light_bits = 16;
    const ReservoirCodec codec(s);
    CHECK_NOTHROW(codec.checkCapacity(65536, "scene.toml"));
    try {
        codec.checkCapacity(100000, "scene.toml");
        FAIL("no error");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        INFO(msg);
        CHECK(msg.find("scene.toml") == 0);
        CHECK(msg.find("needs 17 bits") != std::string::npos);
    }
    s.layout = ReservoirLayout::full;
    CHECK_NOTHROW(ReservoirCodec(s).checkCapacity(100000, "scene.toml"));
}

TEST_CASE("packed reservoirs: field bits, saturation and rounding", "[reservoir][codec]") {
    RestirSettings s;
    s.layout = ReservoirLayout::packed;
    s.light_bits = 20;
    s.half_weights = true;
    const ReservoirCodec half(s);
    CHECK(half.bytes() == 8);
    CHECK(half.maxM() == 4095);
    const StoredReservoir r{0xABCDEu, 1.5f, 37, 0.25f};
    const auto words = half.pack(r);
    CHECK(words[0] == (0xABCDEu | (37u << 20)));
    CHECK(words[1] == (0x3E00u | (0x3400u << 16)));  // half(1.5), half(0.25)
    const StoredReservoir back = half.unpack(words);
    CHECK(back.y == r.y);
    CHECK(back.M == r.M);
    CHECK(back.W == 1.5f);
    CHECK(back.p_hat == 0.25f);
    // M saturates; W beyond the half range saturates to 65504 (not +inf).
    const StoredReservoir big = half.roundTrip({5, 1e6f, 100000, 3.0f});
    CHECK(big.M == 4095);
    CHECK(big.W == 65504.0f);
    // A half keeps 11 significant bits: relative rounding at most 2^-11.
    const StoredReservoir odd = half.roundTrip({5, 1.0f / 3.0f, 1, 0.1f});
    CHECK(std::fabs(odd.W - 1.0f / 3.0f) <= (1.0f / 3.0f) * 0x1p-11f);
    CHECK(odd.W != 1.0f / 3.0f);
    // Empty stays empty.
    CHECK(half.roundTrip(StoredReservoir{}).y == kNoLight);

    s.half_weights = false;
    const ReservoirCodec floats(s);
    CHECK(floats.bytes() == 12);
    CHECK(floats.roundTrip({7, 1.0f / 3.0f, 9, 0.1f}).W == 1.0f / 3.0f);
    s.layout = ReservoirLayout::full;
    CHECK(ReservoirCodec(s).bytes() == 16);
}
