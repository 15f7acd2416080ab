#include "accretion/geometry/billboard.h"

#include "accretion/geometry/camera.h"

namespace accretion {
namespace {

BillboardFrame facingPoint(const Camera& camera, const Vec3& p) {
    Vec3 n = camera.position - p;
    const float len = glm::length(n);
    if (!(len > 0.0f)) return {camera.right, camera.up};
    n /= len;
    Vec3 right = glm::cross(camera.up, n);
    const float rl = glm::length(right);
    if (rl < 1e-6f) return {camera.right, glm::cross(n, camera.right)};
    right /= rl;
    return {right, glm::cross(n, right)};
}

}  // namespace

BillboardFrame billboardFrame(Orientation mode, const Camera& camera, const Vec3& p, const Vec3& v) {
    switch (mode) {
    case Orientation::view_plane: return {camera.right, camera.up};
    case Orientation::view_point: return facingPoint(camera, p);
    case Orientation::velocity: {
        Vec3 n = camera.position - p;
        const float len = glm::length(n);
        if (!(len > 0.0f)) return {camera.right, camera.up};
        n /= len;
        const Vec3 vp = v - glm::dot(v, n) * n;
        const float vl = glm::length(vp);
        if (!(vl > 1e-12f) || !std::isfinite(vl)) return facingPoint(camera, p);
        const Vec3 right = vp / vl;
        return {right, glm::cross(n, right)};
    }
    }
    return {camera.right, camera.up};
}

}  // namespace accretion
