#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "accretion/lighting/reservoir.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// A finalized reservoir as passes and frames exchange it: the sample y, its
/// contribution weight W, confidence M and target p_hat(y) in the domain
/// (pixel, frame) that made it. W = 0 means empty.
struct StoredReservoir {
    std::uint32_t y = kNoLight;
    float W = 0.0f;
    std::uint32_t M = 0;
    float p_hat = 0.0f;

    /// The stored form of a finalized reservoir: its M always, its sample only when W > 0.
    ACC_HD static StoredReservoir of(const Reservoir& r) {
        StoredReservoir s;
        s.M = r.M;
        if (r.W > 0.0f) {
            s.y = r.y;
            s.W = r.W;
            s.p_hat = r.p_hat;
        }
        return s;
    }
};

/// The GPU buffer layout of a stored reservoir. `full`: 16 bytes, exact.
/// `packed`: one 32-bit word with the light index in the low light_bits and
/// M (saturating) above it, then W and p_hat as halves (8 bytes) or floats
/// (12 bytes). Halves saturate at the largest finite half rather than
/// overflowing to infinity. Every buffer write goes through roundTrip(), so
/// the bias of a layout shows in the image.
class ReservoirCodec {
public:
    using Words = std::array<std::uint32_t, 4>;

    explicit ReservoirCodec(const RestirSettings& s)
        : layout_(s.layout), lightBits_(s.light_bits), half_(s.half_weights),
          maxM_(s.layout == ReservoirLayout::full ? 0xffffffffu : (1u << (32 - s.light_bits)) - 1u) {}

    /// Bytes per reservoir in the buffer (inline: the frame plan states it
    /// without linking the codec).
    std::size_t bytes() const { return layout_ == ReservoirLayout::full ? 16 : half_ ? 8 : 12; }
    std::uint32_t maxM() const { return maxM_; }
    /// Throws InputError (naming `where`) if the light index field cannot
    /// address `lights` lights, saying how many bits it needs.
    void checkCapacity(std::size_t lights, std::string_view where) const;
    /// Bits needed to address n lights (at least 1).
    static std::uint32_t bitsFor(std::size_t n);

    Words pack(const StoredReservoir& r) const;
    StoredReservoir unpack(const Words& w) const;
    StoredReservoir roundTrip(const StoredReservoir& r) const { return layout_ == ReservoirLayout::full ? r : unpack(pack(r)); }

private:
    ReservoirLayout layout_;
    std::uint32_t lightBits_;
    bool half_;
    std::uint32_t maxM_;
};

}  // namespace accretion
