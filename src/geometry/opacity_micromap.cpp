#include "accretion/geometry/opacity_micromap.h"

#include <algorithm>
#include <cmath>

namespace accretion {
namespace {

constexpr double kMargin = 1e-6;

double dist2(Vec2 p) {
    const double x = double(p.x) - 0.5, y = double(p.y) - 0.5;
    return x * x + y * y;
}

/// Squared distance from the disc centre to the segment ab.
double segmentDist2(Vec2 a, Vec2 b) {
    const double ax = a.x - 0.5, ay = a.y - 0.5, bx = b.x - 0.5, by = b.y - 0.5;
    const double dx = bx - ax, dy = by - ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? -(ax * dx + ay * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double px = ax + t * dx, py = ay + t * dy;
    return px * px + py * py;
}

/// The centre inside the triangle (either winding)?
bool containsCentre(const std::array<Vec2, 3>& t) {
    auto edge = [](Vec2 a, Vec2 b) { return (double(b.x) - a.x) * (0.5 - a.y) - (double(b.y) - a.y) * (0.5 - a.x); };
    const double e0 = edge(t[0], t[1]), e1 = edge(t[1], t[2]), e2 = edge(t[2], t[0]);
    return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
}

}  // namespace

std::uint32_t OpacityMicromap::microIndex(std::uint32_t level, float u, float v) {
    const std::uint32_t n = 1u << level;
    const float fu = std::clamp(u, 0.0f, 1.0f) * float(n), fv = std::clamp(v, 0.0f, 1.0f) * float(n);
    std::uint32_t j = std::min(n - 1, std::uint32_t(fv));
    std::uint32_t i = std::min(n - 1 - j, std::uint32_t(fu));
    const bool upper = (fu - float(i)) + (fv - float(j)) > 1.0f && i + j + 1 < n;
    return 2 * n * j - j * j + 2 * i + (upper ? 1u : 0u);
}

std::array<Vec2, 3> OpacityMicromap::microCorners(std::uint32_t level, std::uint32_t index) {
    const std::uint32_t n = 1u << level;
    std::uint32_t j = 0;
    while (2 * n * (j + 1) - (j + 1) * (j + 1) <= index) ++j;
    const std::uint32_t within = index - (2 * n * j - j * j);
    const std::uint32_t i = within / 2;
    const float s = 1.0f / float(n);
    const Vec2 p00(float(i) * s, float(j) * s), p10(float(i + 1) * s, float(j) * s), p01(float(i) * s, float(j + 1) * s),
        p11(float(i + 1) * s, float(j + 1) * s);
    if (within % 2 == 0) return {p00, p10, p01};
    return {p10, p11, p01};
}

OmmState OpacityMicromap::classify(const std::array<Vec2, 3>& uv) {
    // The disc is convex: all corners inside means the triangle is inside.
    if (dist2(uv[0]) <= 0.25 - kMargin && dist2(uv[1]) <= 0.25 - kMargin && dist2(uv[2]) <= 0.25 - kMargin)
        return OmmState::opaque;
    // Outside if the centre is outside and every edge is farther than the radius.
    const double r = 0.5 + kMargin;
    if (!containsCentre(uv) && segmentDist2(uv[0], uv[1]) > r * r && segmentDist2(uv[1], uv[2]) > r * r &&
        segmentDist2(uv[2], uv[0]) > r * r)
        return OmmState::transparent;
    return OmmState::unknown;
}

OpacityMicromap::OpacityMicromap(std::uint32_t level, bool fourState) : level_(level), fourState_(fourState) {
    const std::uint32_t m = microTriangles();
    for (std::uint32_t tri = 0; tri < 2; ++tri) {
        states_[tri].resize(m);
        for (std::uint32_t k = 0; k < m; ++k) {
            const auto b = microCorners(level, k);
            const std::array<Vec2, 3> uv{quadUvOf(tri, b[0]), quadUvOf(tri, b[1]), quadUvOf(tri, b[2])};
            OmmState s = classify(uv);
            if (s == OmmState::unknown && !fourState) {
                // 2-state: opaque when at least half the micro-triangle is covered (16x16 barycentric samples).
                constexpr int S = 16;
                int inside = 0, total = 0;
                for (int a = 0; a < S; ++a)
                    for (int c = 0; c < S - a; ++c) {
                        const float wa = (a + 1.0f / 3.0f) / S, wc = (c + 1.0f / 3.0f) / S;
                        const Vec2 p = uv[0] + wa * (uv[1] - uv[0]) + wc * (uv[2] - uv[0]);
                        inside += dist2(p) <= 0.25;
                        ++total;
                    }
                s = 2 * inside >= total ? OmmState::opaque : OmmState::transparent;
            }
            states_[tri][k] = s;
        }
    }
}

std::uint64_t OpacityMicromap::count(OmmState s) const {
    std::uint64_t n = 0;
    for (const auto& st : states_) n += std::uint64_t(std::count(st.begin(), st.end(), s));
    return n;
}

std::uint64_t OpacityMicromap::arrayBytes() const {
    const std::uint64_t bits = std::uint64_t(microTriangles()) * (fourState_ ? 2u : 1u);
    return (bits + 7) / 8;
}

OmmMemory ommMemory(const OpacityMicromap& omm, std::uint64_t billboards) {
    OmmMemory m;
    const std::uint64_t triangles = 2 * billboards;
    m.sharedBytes = 2 * omm.arrayBytes() + 2 * triangles;  // two arrays + a 16-bit index per triangle
    m.perTriangleBytes = triangles * omm.arrayBytes() + 4 * triangles;  // an array + a 32-bit index per triangle
    return m;
}

}  // namespace accretion
