#include "accretion/lighting/reservoir_codec.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <Imath/half.h>
#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {
namespace {

std::uint32_t toHalfBits(float v) {
    constexpr float kHalfMax = 65504.0f;
    const float clamped = std::isfinite(v) ? std::clamp(v, -kHalfMax, kHalfMax) : 0.0f;
    return Imath::half(clamped).bits();
}

float fromHalfBits(std::uint32_t b) {
    Imath::half h;
    h.setBits(static_cast<unsigned short>(b & 0xffffu));
    return static_cast<float>(h);
}

}  // namespace

std::uint32_t ReservoirCodec::bitsFor(std::size_t n) { return indexBits(n); }

void ReservoirCodec::checkCapacity(std::size_t lights, std::string_view where) const {
    if (layout_ == ReservoirLayout::full) return;
    if (lights > (std::uint64_t(1) << lightBits_))
        throw InputError(fmt::format(
            "{}: restir.light_bits = {} addresses {} lights but the frame has {} particles: the packed layout needs {} bits",
            where, lightBits_, std::uint64_t(1) << lightBits_, lights, bitsFor(lights)));
}

ReservoirCodec::Words ReservoirCodec::pack(const StoredReservoir& r) const {
    Words w{};
    if (layout_ == ReservoirLayout::full) {
        w = {r.y, std::bit_cast<std::uint32_t>(r.W), r.M, std::bit_cast<std::uint32_t>(r.p_hat)};
        return w;
    }
    const std::uint32_t mask = lightBits_ >= 32 ? 0xffffffffu : (1u << lightBits_) - 1u;
    const std::uint32_t y = r.W > 0.0f ? (r.y & mask) : 0u;
    w[0] = y | (std::min(r.M, maxM_) << lightBits_);
    if (half_) {
        w[1] = toHalfBits(r.W) | (toHalfBits(r.p_hat) << 16);
    } else {
        w[1] = std::bit_cast<std::uint32_t>(r.W);
        w[2] = std::bit_cast<std::uint32_t>(r.p_hat);
    }
    return w;
}

StoredReservoir ReservoirCodec::unpack(const Words& w) const {
    if (layout_ == ReservoirLayout::full)
        return {w[0], std::bit_cast<float>(w[1]), w[2], std::bit_cast<float>(w[3])};
    const std::uint32_t mask = (1u << lightBits_) - 1u;
    StoredReservoir r;
    r.M = w[0] >> lightBits_;
    if (half_) {
        r.W = fromHalfBits(w[1]);
        r.p_hat = fromHalfBits(w[1] >> 16);
    } else {
        r.W = std::bit_cast<float>(w[1]);
        r.p_hat = std::bit_cast<float>(w[2]);
    }
    r.y = r.W > 0.0f ? (w[0] & mask) : kNoLight;
    return r;
}

}  // namespace accretion
