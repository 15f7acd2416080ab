#pragma once
#include <cstdint>

#include "accretion/core/gbuffer_texel_layout.h"
#include "accretion/core/math.h"
#include "accretion/geometry/billboard.h"
#include "accretion/geometry/camera.h"
#include "accretion/scene/settings.h"

namespace accretion {

// A G-buffer texel from a primary hit (the CPU's traceGBuffer and the OptiX
// twin's raygen share these): the tracer decides which particle j the pixel
// ray (x, y) hits; the point on it is found again in double along the pixel
// ray, relative to the particle (local = x - p_j), so that its error is that
// of the inputs, not of the ray length or the coordinates. dir is the float
// pixel direction that was traced.

/// A billboard hit (frame f, quad uv of the tracer's hit: used only if the
/// pixel ray lies in the quad's plane).
ACC_HD inline GBufferTexel billboardTexel(const Camera& camera, std::uint32_t x, std::uint32_t y, const Vec3& dir,
                                          std::uint32_t j, const Vec3& p, float rj, const BillboardFrame& f, Vec2 hitUv,
                                          ShadingModel model) {
    GBufferTexel g;
    g.particle = j;
    const DVec3 o = DVec3(camera.position) - DVec3(p), ray = camera.pixelRay(x, y);  // o relative to p_j
    const DVec3 R(f.right), U(f.up), N = glm::cross(R, U);
    const double denom = glm::dot(N, ray);
    const DVec3 local = denom != 0.0 ? o - (glm::dot(N, o) / denom) * ray
                                     : (2.0 * double(hitUv.x) - 1.0) * double(rj) * R +
                                           (2.0 * double(hitUv.y) - 1.0) * double(rj) * U;
    g.local = Vec3(local);
    g.geomNormal = glm::normalize(f.normal());
    if (glm::dot(g.geomNormal, dir) > 0.0f) g.geomNormal = -g.geomNormal;
    if (model == ShadingModel::sphere) {
        const Vec2 uv(glm::clamp(0.5 + 0.5 * glm::dot(local, R) / double(rj), 0.0, 1.0),
                      glm::clamp(0.5 + 0.5 * glm::dot(local, U) / double(rj), 0.0, 1.0));
        g.normal = impostorNormal(f, uv);
    } else {
        g.normal = g.geomNormal;
    }
    g.depth = glm::dot((p + g.local) - camera.position, camera.forward);
    return g;
}

/// A sphere hit at ray distance hitT: the near root of |o + t ray| = r, or
/// the tracer's point when the double test grazes past (then only on the
/// silhouette).
ACC_HD inline GBufferTexel sphereTexel(const Camera& camera, std::uint32_t x, std::uint32_t y, const Vec3& dir,
                                       std::uint32_t j, const Vec3& p, float rj, float hitT) {
    GBufferTexel g;
    g.particle = j;
    const DVec3 o = DVec3(camera.position) - DVec3(p), ray = camera.pixelRay(x, y);
    const double b = glm::dot(o, ray), c = glm::dot(o, o) - double(rj) * double(rj);
    const double disc = b * b - c;
    DVec3 local;
    if (disc >= 0.0) {
        const double t0 = -b - sqrt(disc);
        local = o + (t0 > 0.0 ? t0 : -b + sqrt(disc)) * ray;
    } else {
        local = o + double(hitT) * DVec3(dir);
    }
    const double len = glm::length(local);
    const DVec3 n = len > 0.0 ? local / len : -ray;
    g.local = Vec3(double(rj) * n);
    g.normal = g.geomNormal = Vec3(n);
    g.depth = glm::dot((p + g.local) - camera.position, camera.forward);
    return g;
}

}  // namespace accretion
