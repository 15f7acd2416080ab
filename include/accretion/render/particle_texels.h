#pragma once
// The lighting grid of particle_restir (docs/MODEL.md section 4b): texels on
// the billboards of the particles the frame sees, not pixels. Each visible
// particle has a slot; its texelsPerParticle() texels are consecutive in the
// grid (layer by layer, each layer side x side texels at uv centres
// ((i + 0.5) / side, (j + 0.5) / side)). Slots follow the particles' Morton
// order in world space, so that the slots either side of one hold its world
// neighbours (spatial reuse) and a warp's texels lie close together. The
// helpers marked ACC_HD are the CPU's and the twin's alike.
#include <cstdint>
#include <limits>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/geometry/billboard.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/scene/settings.h"

namespace accretion {

inline constexpr std::uint32_t kNoSlot = 0xffffffffu;

/// The grid's width: 8 texels a row, so that an 8x8 thread group is 64
/// consecutive texels and a warp 32 (a 1D launch over the texels).
inline constexpr std::uint32_t kTexelRowWidth = 8;

/// 21 bits per axis of a point in [0, 1]^3, interleaved (z y x, x lowest).
ACC_HD inline std::uint64_t mortonKey(const Vec3& unit) {
    auto spread = [](std::uint64_t v) {
        v &= 0x1fffff;
        v = (v | v << 32) & 0x1f00000000ffffull;
        v = (v | v << 16) & 0x1f0000ff0000ffull;
        v = (v | v << 8) & 0x100f00f00f00f00full;
        v = (v | v << 4) & 0x10c30c30c30c30c3ull;
        v = (v | v << 2) & 0x1249249249249249ull;
        return v;
    };
    auto q = [](float c) {
        const float s = c * 2097151.0f;
        return std::uint64_t(s > 0.0f ? (s < 2097151.0f ? s : 2097151.0f) : 0.0f);
    };
    return spread(q(unit.x)) | spread(q(unit.y)) << 1 | spread(q(unit.z)) << 2;
}

/// The cube Morton keys are taken over: the particles' bounds, its edge the longest side.
struct MortonFrame {
    Vec3 lo{0.0f};
    float inv = 0.0f;  ///< 1 / edge (0 for one point)
    ACC_HD std::uint64_t key(const Vec3& p) const { return mortonKey((p - lo) * inv); }
};
inline MortonFrame mortonFrame(const Vec3* position, std::size_t n) {
    Vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t j = 0; j < n; ++j) {
        lo = glm::min(lo, position[j]);
        hi = glm::max(hi, position[j]);
    }
    if (n == 0) return {};
    const Vec3 e = hi - lo;
    const float edge = e.x > e.y ? (e.x > e.z ? e.x : e.z) : (e.y > e.z ? e.y : e.z);
    return {lo, edge > 0.0f ? 1.0f / edge : 0.0f};
}

/// The uv centre of texel `sub` (its place in a layer: row-major) of a side x side billboard grid.
ACC_HD inline Vec2 texelUv(std::uint32_t sub, std::uint32_t side) {
    return Vec2((float(sub % side) + 0.5f) / float(side), (float(sub / side) + 0.5f) / float(side));
}

/// Where a texel's receiver lies on its billboard in a frame
/// (particle_split.texel_point): its centre (texelUv); jittered, a point
/// drawn afresh each frame, by particle id, texel and frame, uniform in the
/// texel's square of the billboard and, with `disc` (alpha disc), inside
/// the disc (the square's part in it: rejection, at most kTexelPointTries
/// draws, then the centre); antithetic, such a point c + d in even frames
/// and its mirror c - d about the texel's centre c in the next (d drawn
/// once a pair of frames; with `disc` both inside it). A texel averaged
/// over frames then holds the mean of the light over that area, the area
/// its pixels see, not the light at one point of it; the mirrored pairs
/// cancel the light's linear change across it, which the jittered points
/// add as noise.
struct TexelPointRule {
    TexelPoint mode = TexelPoint::centre;
    bool disc = false;
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
};
inline constexpr std::uint32_t kTexelPointTries = 16;

/// Texel `sub`'s receiver uv on particle j's side x side grid under `rule`.
ACC_HD inline Vec2 texelPointUv(std::uint32_t j, std::uint32_t sub, std::uint32_t side, const TexelPointRule& rule) {
    const Vec2 centre = texelUv(sub, side);
    if (rule.mode == TexelPoint::centre) return centre;
    const bool pairs = rule.mode == TexelPoint::antithetic;
    PortableRng rng(std::uint64_t(j) * side * side + sub, pairs ? rule.frame / 2 : rule.frame, RngPass::texelPoint, rule.seed);
    const float inv = 1.0f / float(side), sign = pairs && (rule.frame & 1u) ? -1.0f : 1.0f;
    for (std::uint32_t k = 0; k < kTexelPointTries; ++k) {
        const float u = rng.uniform();  // u before v: in one expression the host's and nvcc's orders differ
        const float v = rng.uniform();
        const Vec2 d((u - 0.5f) * inv, (v - 0.5f) * inv);
        const Vec2 uv = centre + sign * d;
        if (!rule.disc || (insideDisc(uv) && (!pairs || insideDisc(centre - sign * d)))) return uv;
    }
    return centre;
}

/// The receiver at billboard uv of particle j (at p, radius r, frame f) as
/// the camera sees it: the point p + (2u - 1) r right + (2v - 1) r up, the
/// billboard's normal towards the camera (the impostor's at uv for the
/// sphere model), its camera-space depth; what billboardTexel gives a pixel
/// ray through that point.
ACC_HD inline GBufferTexel billboardPointTexel(const Camera& camera, std::uint32_t j, const Vec3& p, float r,
                                               const BillboardFrame& f, Vec2 uv, ShadingModel model) {
    GBufferTexel g;
    g.particle = j;
    const DVec3 R(f.right), U(f.up);
    g.local = Vec3((2.0 * double(uv.x) - 1.0) * double(r) * R + (2.0 * double(uv.y) - 1.0) * double(r) * U);
    g.geomNormal = glm::normalize(f.normal());
    if (glm::dot(g.geomNormal, (p + g.local) - camera.position) > 0.0f) g.geomNormal = -g.geomNormal;
    g.normal = model == ShadingModel::sphere ? impostorNormal(f, uv) : g.geomNormal;
    g.depth = glm::dot((p + g.local) - camera.position, camera.forward);
    return g;
}

/// The billboard uv of a pixel's receiver on particle j (radius r, frame f): inverse of billboardPointTexel.
ACC_HD inline Vec2 billboardUv(const Vec3& local, float r, const BillboardFrame& f) {
    const float inv = 0.5f / r;
    return Vec2(0.5f + glm::dot(local, f.right) * inv, 0.5f + glm::dot(local, f.up) * inv);
}

/// Bilinear interpolation over a side x side texel grid at uv: the (up to)
/// four texels sub[k] of a layer and their weights w[k] (sum 1), clamped at
/// the billboard's edges. Returns how many (1 for side 1).
ACC_HD inline std::uint32_t bilinearTexels(Vec2 uv, std::uint32_t side, std::uint32_t sub[4], float w[4]) {
    if (side == 1) {
        sub[0] = 0;
        w[0] = 1.0f;
        return 1;
    }
    const float last = float(side - 1);
    const float tx = glm::clamp(uv.x * float(side) - 0.5f, 0.0f, last), ty = glm::clamp(uv.y * float(side) - 0.5f, 0.0f, last);
    const std::uint32_t x0 = std::uint32_t(tx) < side - 1 ? std::uint32_t(tx) : side - 2;
    const std::uint32_t y0 = std::uint32_t(ty) < side - 1 ? std::uint32_t(ty) : side - 2;
    const float fx = tx - float(x0), fy = ty - float(y0);
    sub[0] = y0 * side + x0;
    sub[1] = sub[0] + 1;
    sub[2] = sub[0] + side;
    sub[3] = sub[2] + 1;
    w[0] = (1.0f - fx) * (1.0f - fy);
    w[1] = fx * (1.0f - fy);
    w[2] = (1.0f - fx) * fy;
    w[3] = fx * fy;
    return 4;
}

/// The texels a pixel at billboard uv reads, of the particle whose first
/// texel is `base` (texelsPerParticle = side x side x layers, layer by
/// layer): the bilinear four (one for side 1) of each layer, weights
/// summing to 1 over all of them. q and w hold 4 x layers entries. Returns how many.
ACC_HD inline std::uint32_t texelStencil(Vec2 uv, std::uint32_t side, std::uint32_t layers, std::size_t base, std::size_t* q,
                                         float* w) {
    std::uint32_t sub[4];
    float bw[4];
    const std::uint32_t k = bilinearTexels(uv, side, sub, bw);
    const std::uint32_t perLayer = side * side;
    std::uint32_t n = 0;
    for (std::uint32_t layer = 0; layer < layers; ++layer)
        for (std::uint32_t c = 0; c < k; ++c) {
            q[n] = base + layer * perLayer + sub[c];
            w[n++] = bw[c] / float(layers);
        }
    return n;
}

}  // namespace accretion
