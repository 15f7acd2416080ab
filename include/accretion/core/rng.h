#pragma once
#include <cstdint>

#include <pcg_random.hpp>

#include "accretion/core/math.h"

namespace accretion {

/// Fixed pass ids for random streams: a new pass never shifts another's numbers.
enum class RngPass : std::uint32_t {
    particles = 1,      ///< particle generator
    lightSampling = 2,  ///< uniform / power / tree light selection, ris
    restirCandidates = 3,  ///< restir: initial candidates
    restirTemporal = 4,    ///< restir: temporal resampling
    restirSpatial = 5,     ///< restir: spatial neighbours and resampling (item mixes the iteration)
    presampleTiles = 6,    ///< light tiles: one entry's power draw
    presampleRegir = 7,    ///< ReGIR grid: one slot's RIS (and a slot group's tile)
    tileSelection = 8,     ///< light tiles: the tile of a pixel block
    nearLightPilot = 9,    ///< split: the far samples of the pilot that picks k
    voxelCache = 10,       ///< voxel_cache: a cell's light draws
    particleSplit = 11,    ///< particle_split: a texel's far draws
    texelPoint = 12,       ///< particle_split.texel_point jittered and antithetic: a texel's receiver on its billboard
};

/// 64-bit finaliser (SplitMix64), a bijection with good avalanche.
constexpr std::uint64_t mix64(std::uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

/// Hash of (item, frame, pass, seed[, sub]) selecting one independent
/// stream; `sub` != 0 splits an item's stream further (sample chunks).
constexpr std::uint64_t streamKey(std::uint64_t item, std::uint32_t frame, RngPass pass, std::uint64_t seed,
                                  std::uint64_t sub = 0) {
    std::uint64_t h = mix64(seed);
    h = mix64(h ^ static_cast<std::uint64_t>(pass));
    h = mix64(h ^ frame);
    h = mix64(h ^ item);
    return sub ? mix64(h ^ sub) : h;
}

/// A bound n of uniform integers in [0, n), with the two divisions of
/// pcg's bounded_rand done once: Rng::uniformInt(IntBound) draws the same
/// numbers as Rng::uniformInt(n) (the same rejection threshold, then r mod n
/// by Lemire, Kaser & Kurz's exact 32-bit remainder: two multiplications).
struct IntBound {
    std::uint32_t n = 1;
    std::uint32_t threshold = 0;  ///< 2^32 mod n: draws below it are rejected
    std::uint64_t m = 0;          ///< ceil(2^64 / n) (0 for n = 1)

    IntBound() = default;
    explicit IntBound(std::uint32_t bound)
        : n(bound), threshold((0u - bound) % bound), m(~std::uint64_t(0) / bound + 1) {}
    /// r mod n, exact for every 32-bit r.
    std::uint32_t mod(std::uint32_t r) const {
        const std::uint64_t low = m * r;
        return static_cast<std::uint32_t>((static_cast<unsigned __int128>(low) * n) >> 64);
    }
};

/// PCG32 stream of one pixel (or particle) in one pass of one frame.
class Rng {
public:
    Rng(std::uint64_t item, std::uint32_t frame, RngPass pass, std::uint64_t seed, std::uint64_t sub = 0)
        : pcg_(streamKey(item, frame, pass, seed, sub), mix64(item ^ (std::uint64_t(frame) << 32))) {}

    /// Uniform float in [0, 1).
    float uniform() { return static_cast<float>(pcg_() >> 8) * 0x1p-24f; }
    /// Uniform integer in [0, n).
    std::uint32_t uniformInt(std::uint32_t n) { return pcg_(n); }
    /// The same number as uniformInt(b.n), without divisions.
    std::uint32_t uniformInt(const IntBound& b) {
        for (;;) {
            const std::uint32_t r = pcg_();
            if (r >= b.threshold) return b.mod(r);
        }
    }
    std::uint32_t next() { return pcg_(); }

private:
    pcg32 pcg_;
};

/// The stream of Rng in plain 64-bit arithmetic, for GPU code (the OptiX
/// twin, src/twin): PCG32 (XSH-RR, 64-bit state, the stream's odd increment)
/// seeded as pcg-cpp seeds pcg32, with pcg-cpp's bounded_rand. It draws the
/// same numbers as Rng (tests/core/rng_test.cpp checks it against pcg-cpp).
class PortableRng {
public:
    ACC_HD PortableRng(std::uint64_t item, std::uint32_t frame, RngPass pass, std::uint64_t seed, std::uint64_t sub = 0)
        : inc_((mix64(item ^ (std::uint64_t(frame) << 32)) << 1) | 1u) {
        state_ = (streamKey(item, frame, pass, seed, sub) + inc_) * kMultiplier + inc_;
    }
    ACC_HD std::uint32_t next() {
        const std::uint64_t old = state_;
        state_ = old * kMultiplier + inc_;
        const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((0u - rot) & 31u));
    }
    ACC_HD float uniform() { return static_cast<float>(next() >> 8) * 0x1p-24f; }
    ACC_HD std::uint32_t uniformInt(std::uint32_t n) {
        const std::uint32_t threshold = (0u - n) % n;
        for (;;) {
            const std::uint32_t r = next();
            if (r >= threshold) return r % n;
        }
    }

private:
    static constexpr std::uint64_t kMultiplier = 6364136223846793005ull;
    std::uint64_t inc_;
    std::uint64_t state_;
};

}  // namespace accretion
