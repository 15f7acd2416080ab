#include "accretion/geometry/clustering.h"

#include <algorithm>
#include <array>
#include <bit>
#include <limits>

#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

namespace accretion {
namespace {

constexpr int kBits = 10;  // Morton grid 1024^3

std::uint32_t spreadBits(std::uint32_t x) {
    x &= 0x3ff;
    x = (x | (x << 16)) & 0x030000ff;
    x = (x | (x << 8)) & 0x0300f00f;
    x = (x | (x << 4)) & 0x030c30c3;
    x = (x | (x << 2)) & 0x09249249;
    return x;
}

/// (Morton code << 32 | index) of every position in its bounding cube,
/// sorted (ties broken by index: deterministic).
std::vector<std::uint64_t> sortedMortonKeys(std::span<const Vec3> positions) {
    const std::size_t n = positions.size();
    using Box = std::pair<Vec3, Vec3>;
    const Box empty{Vec3(std::numeric_limits<float>::max()), Vec3(-std::numeric_limits<float>::max())};
    const Box box = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, n, 16384), empty,
        [&](const auto& r, Box b) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                b.first = glm::min(b.first, positions[i]);
                b.second = glm::max(b.second, positions[i]);
            }
            return b;
        },
        [](const Box& a, const Box& b) { return Box{glm::min(a.first, b.first), glm::max(a.second, b.second)}; });
    const Vec3 lo = box.first, hi = box.second;
    const Vec3 ext = hi - lo;
    const float size = std::max({ext.x, ext.y, ext.z, 1e-30f});
    const float scale = float((1 << kBits) - 1) / size;
    std::vector<std::uint64_t> keys(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3 q = (positions[i] - lo) * scale;
            const std::uint32_t code = spreadBits(std::uint32_t(q.x)) | (spreadBits(std::uint32_t(q.y)) << 1) |
                                       (spreadBits(std::uint32_t(q.z)) << 2);
            keys[i] = (std::uint64_t(code) << 32) | i;
        }
    });
    tbb::parallel_sort(keys.begin(), keys.end());
    return keys;
}

/// The finest level whose non-empty cells average >= target particles. One
/// pass: neighbours whose keys first differ at bit d are in different
/// cells at every level l with 32 + 3 l <= d.
int clusterLevel(const std::vector<std::uint64_t>& keys, std::uint32_t target) {
    const std::size_t n = keys.size();
    using Histogram = std::array<std::size_t, kBits + 1>;
    const Histogram firstDiff = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(1, std::max<std::size_t>(n, 1), 16384), Histogram{},
        [&](const auto& r, Histogram h) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const std::uint64_t x = (keys[i] ^ keys[i - 1]) >> 32;
                if (x == 0) continue;
                const int d = 63 - std::countl_zero(x);  // highest differing bit of the Morton code
                ++h[std::min(kBits, d / 3)];
            }
            return h;
        },
        [](Histogram a, const Histogram& b) {
            for (int l = 0; l <= kBits; ++l) a[l] += b[l];
            return a;
        });
    for (int l = 0; l <= kBits; ++l) {
        std::size_t cells = 1;
        for (int m = l; m <= kBits; ++m) cells += firstDiff[m];
        if (double(n) / double(cells) >= double(target)) return l;
    }
    return kBits;  // cell = 2^level Morton units per axis; kBits = one cell
}

}  // namespace

Clusters clusterParticles(std::span<const Vec3> positions, std::uint32_t target) {
    Clusters out;
    const std::size_t n = positions.size();
    out.offset.push_back(0);
    if (n == 0) return out;
    target = std::max<std::uint32_t>(target, 1);
    const std::vector<std::uint64_t> keys = sortedMortonKeys(positions);
    const int shift = 32 + 3 * clusterLevel(keys, target);
    out.particle.resize(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16384), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) out.particle[i] = std::uint32_t(keys[i] & 0xffffffffu);
    });
    // Each cell of the level, cut into parts of about `target` particles.
    std::size_t begin = 0;
    for (std::size_t i = 1; i <= n; ++i) {
        if (i < n && (keys[i] >> shift) == (keys[i - 1] >> shift)) continue;
        const std::size_t cellSize = i - begin;
        const std::size_t parts = (cellSize + target - 1) / target;
        for (std::size_t k = 1; k <= parts; ++k) out.offset.push_back(std::uint32_t(begin + cellSize * k / parts));
        begin = i;
    }
    return out;
}

}  // namespace accretion
