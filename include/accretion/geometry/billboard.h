#pragma once
#include "accretion/core/math.h"
#include "accretion/scene/settings.h"

namespace accretion {

struct Camera;

/// Orientation of one billboard quad: corners p +- r right +- r up, uv (0,0)
/// at p - r right - r up; normal = right x up faces the camera.
struct BillboardFrame {
    Vec3 right;
    Vec3 up;
    ACC_HD Vec3 normal() const { return glm::cross(right, up); }
};

/// The frame of a billboard at p moving with v (docs/MODEL.md section 2):
/// view_plane: the image plane; view_point: facing the eye; velocity: facing
/// the eye with `right` along the projected velocity (view_point if v is 0).
BillboardFrame billboardFrame(Orientation mode, const Camera& camera, const Vec3& p, const Vec3& v);

/// Quad uv in [0,1]^2 from the barycentrics (u, v) of triangle `primID`
/// (0,1,2) or (0,2,3) with uv corners (0,0), (1,0), (1,1), (0,1).
ACC_HD inline Vec2 quadUv(unsigned primID, float u, float v) {
    return (primID & 1u) ? Vec2(u, u + v) : Vec2(u + v, v);
}

/// The GPU's triangle of a quad uv, (0,1,2) below the diagonal (u >= v) or
/// (0,2,3) above, and the barycentrics (u, v) on it (inverse of quadUv).
inline unsigned quadTriangle(Vec2 uv, Vec2& bary) {
    if (uv.x >= uv.y) {
        bary = Vec2(uv.x - uv.y, uv.y);
        return 0;
    }
    bary = Vec2(uv.x, uv.y - uv.x);
    return 1;
}

/// Inside the inscribed disc of the quad (the `disc` alpha test).
ACC_HD inline bool insideDisc(Vec2 uv) {
    const Vec2 c = uv - Vec2(0.5f);
    return glm::dot(c, c) <= 0.25f;
}

/// The billboard as a procedural primitive (the aabbs layout's intersection
/// program on the GPU, the CPU's box primitives): where o + t d, t in
/// [tmin, tmax], meets the plane of the quad p -+ r right -+ r up inside the
/// quad (and inside the disc when `disc`); t and the quad uv.
ACC_HD inline bool intersectBillboard(const Vec3& o, const Vec3& d, float tmin, float tmax, const Vec3& p, float r,
                                      const BillboardFrame& f, bool disc, float& t, Vec2& uv) {
    const Vec3 n = f.normal();
    const float denom = glm::dot(n, d);
    if (denom == 0.0f) return false;
    t = glm::dot(n, p - o) / denom;
    if (!(t >= tmin && t <= tmax)) return false;
    const Vec3 h = o + t * d - p;
    const float inv = 0.5f / r;
    uv = Vec2(0.5f + glm::dot(h, f.right) * inv, 0.5f + glm::dot(h, f.up) * inv);
    if (uv.x < 0.0f || uv.x > 1.0f || uv.y < 0.0f || uv.y > 1.0f) return false;
    return !disc || insideDisc(uv);
}

/// The bounds of a billboard's quad: p -+ r (|right| + |up|) per axis.
ACC_HD inline Vec3 billboardExtent(float r, const BillboardFrame& f) { return r * (glm::abs(f.right) + glm::abs(f.up)); }

/// Normal of the sphere impostor at quad uv: (x, y, sqrt(1-x^2-y^2)) in the
/// billboard frame, x, y = 2 uv - 1, clamped to the rim (z = 0) outside the
/// disc. In double: near the rim z moves fast with uv.
ACC_HD inline Vec3 impostorNormal(const BillboardFrame& f, Vec2 uv) {
    double x = 2.0 * double(uv.x) - 1.0, y = 2.0 * double(uv.y) - 1.0;
    const double q2 = x * x + y * y;
    double z = 0.0;
    if (q2 > 1.0) {
        const double len = std::sqrt(q2);
        x /= len, y /= len;
    } else {
        z = std::sqrt(1.0 - q2);
    }
    const DVec3 right(f.right), up(f.up);
    return Vec3(glm::normalize(x * right + y * up + z * glm::cross(right, up)));
}

}  // namespace accretion
