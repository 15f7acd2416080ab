#include "support/oracle.h"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace accretion::test {
namespace {

using D3 = glm::dvec3;

D3 d3(const glm::vec3& v) { return D3(double(v.x), double(v.y), double(v.z)); }

constexpr double kPi = 3.14159265358979323846;

/// The pinhole camera of docs/MODEL.md section 1, in double.
struct OracleCamera {
    D3 eye, forward, right, up;
    double tanHalf = 0.0, aspect = 1.0;
    std::uint32_t width = 0, height = 0;

    explicit OracleCamera(const CameraSettings& c) : width(c.width), height(c.height) {
        eye = d3(c.position);
        forward = glm::normalize(d3(c.look_at) - eye);
        right = glm::normalize(glm::cross(forward, d3(c.up)));
        up = glm::cross(right, forward);
        tanHalf = std::tan(0.5 * c.fov * kPi / 180.0);
        aspect = double(c.width) / double(c.height);
    }
    /// The ray through the centre of pixel (x, y), y = 0 the top row.
    D3 direction(std::uint32_t x, std::uint32_t y) const {
        const double sx = ((double(x) + 0.5) / double(width) * 2.0 - 1.0) * tanHalf * aspect;
        const double sy = (1.0 - (double(y) + 0.5) / double(height) * 2.0) * tanHalf;
        return glm::normalize(forward + sx * right + sy * up);
    }
};

/// A billboard's unit in-plane axes; right x up faces the camera.
struct Axes {
    D3 right, up, normal;
};

Axes facingEye(const OracleCamera& cam, const D3& p) {
    D3 n = cam.eye - p;
    const double len = glm::length(n);
    if (!(len > 0.0)) return {cam.right, cam.up, glm::cross(cam.right, cam.up)};
    n /= len;
    D3 right = glm::cross(cam.up, n);
    const double rl = glm::length(right);
    if (rl < 1e-6) {
        const D3 up = glm::cross(n, cam.right);
        return {cam.right, up, glm::cross(cam.right, up)};
    }
    right /= rl;
    return {right, glm::cross(n, right), n};
}

/// docs/MODEL.md section 2: view_plane (image plane), view_point (facing the
/// eye, right perpendicular to the camera's up), velocity (facing the eye,
/// right along the velocity projected onto the facing plane).
Axes billboardAxes(Orientation mode, const OracleCamera& cam, const D3& p, const D3& v) {
    switch (mode) {
    case Orientation::view_plane: return {cam.right, cam.up, glm::cross(cam.right, cam.up)};
    case Orientation::view_point: return facingEye(cam, p);
    case Orientation::velocity: {
        D3 n = cam.eye - p;
        const double len = glm::length(n);
        if (!(len > 0.0)) return {cam.right, cam.up, glm::cross(cam.right, cam.up)};
        n /= len;
        const D3 vp = v - glm::dot(v, n) * n;
        const double vl = glm::length(vp);
        if (!(vl > 1e-12)) return facingEye(cam, p);
        const D3 right = vp / vl;
        return {right, glm::cross(n, right), n};
    }
    }
    return {cam.right, cam.up, glm::cross(cam.right, cam.up)};
}

struct Body {
    D3 p;
    double r;
    Axes axes;
};

/// A crossing of a line o + t dir with one particle's geometry: the smallest
/// t > tmin (or the two roots of a sphere), and how far inside the
/// silhouette it lies, relative to the radius (negative: outside).
struct Crossing {
    double t[2] = {0.0, 0.0};
    int count = 0;     ///< roots that exist (the plane: 1, a sphere: 0 or 2)
    double inside = -1.0;
};

Crossing crossQuad(const Body& b, bool disc, const D3& o, const D3& dir) {
    Crossing c;
    const double denom = glm::dot(b.axes.normal, dir);
    if (denom == 0.0) return c;  // in the plane: no crossing
    const double t = glm::dot(b.axes.normal, b.p - o) / denom;
    const D3 h = o + t * dir - b.p;
    const double u = glm::dot(h, b.axes.right) / b.r, v = glm::dot(h, b.axes.up) / b.r;
    c.t[0] = t;
    c.count = 1;
    c.inside = disc ? 1.0 - std::sqrt(u * u + v * v) : 1.0 - std::max(std::fabs(u), std::fabs(v));
    return c;
}

Crossing crossSphere(const Body& b, const D3& o, const D3& dir) {
    Crossing c;
    const double a = glm::dot(dir, dir);
    const D3 oc = o - b.p;
    const double half = glm::dot(oc, dir) / a;
    const double closest2 = std::max(0.0, glm::dot(oc, oc) - half * half * a);  // squared distance of the line
    c.inside = 1.0 - std::sqrt(closest2) / b.r;
    if (closest2 > b.r * b.r) return c;
    const double s = std::sqrt((b.r * b.r - closest2) / a);
    c.t[0] = -half - s;
    c.t[1] = -half + s;
    c.count = 2;
    return c;
}

}  // namespace

std::size_t OracleImage::hits() const {
    return std::size_t(std::count_if(particle.begin(), particle.end(), [](std::uint32_t j) { return j != kOracleMiss; }));
}

OracleImage oracleRender(const Settings& s, const Particles& particles, double margin) {
    const OracleCamera cam(s.camera);
    const std::size_t n = particles.size();
    const bool spheres = s.geometry.primitive == Primitive::sphere;
    const bool disc = s.geometry.alpha == AlphaMode::disc && !spheres;
    std::vector<Body> bodies(n);
    for (std::size_t k = 0; k < n; ++k) {
        const D3 p = d3(particles.position[k]);
        bodies[k] = {p, double(particles.radius[k]), billboardAxes(s.geometry.orientation, cam, p, d3(particles.velocity[k]))};
    }
    auto cross = [&](std::size_t k, const D3& o, const D3& dir) {
        return spheres ? crossSphere(bodies[k], o, dir) : crossQuad(bodies[k], disc, o, dir);
    };

    OracleImage img;
    img.width = cam.width;
    img.height = cam.height;
    const std::size_t pixels = std::size_t(cam.width) * cam.height;
    img.particle.assign(pixels, kOracleMiss);
    img.Lr.assign(pixels, D3(0.0));
    img.grazing.assign(pixels, 0);

    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, pixels, 16), [&](const auto& range) {
        for (std::size_t px = range.begin(); px != range.end(); ++px) {
            const D3 dir = cam.direction(std::uint32_t(px % cam.width), std::uint32_t(px / cam.width));

            // Primary ray: the nearest crossing with t > 0 inside a silhouette.
            std::size_t j = n;
            double tj = INFINITY;
            for (std::size_t k = 0; k < n; ++k) {
                const Crossing c = cross(k, cam.eye, dir);
                if (c.inside < 0.0) continue;
                for (int q = 0; q < c.count; ++q)
                    if (c.t[q] > 0.0 && c.t[q] < tj) {
                        tj = c.t[q];
                        j = k;
                        break;
                    }
            }
            bool grazing = false;
            for (std::size_t k = 0; k < n && !grazing; ++k) {
                if (k == j) continue;
                const Crossing c = cross(k, cam.eye, dir);
                for (int q = 0; q < c.count; ++q) {
                    if (!(c.t[q] > 0.0) || c.t[q] > tj * (1.0 + margin)) continue;
                    // An edge the ray grazes in front of the hit, or a tie in depth.
                    if (std::fabs(c.inside) < margin || (c.inside >= 0.0 && c.t[q] > tj * (1.0 - margin))) grazing = true;
                }
            }
            if (j == n) {
                img.grazing[px] = grazing;
                continue;
            }
            img.particle[px] = std::uint32_t(j);
            const Body& rb = bodies[j];
            const D3 x = cam.eye + tj * dir;

            // Shading normal (docs/MODEL.md section 3).
            D3 nrm;
            if (spheres) {
                nrm = glm::normalize(x - rb.p);
            } else if (s.shading.model == ShadingModel::sphere) {
                const D3 h = x - rb.p;
                double u = glm::dot(h, rb.axes.right) / rb.r, v = glm::dot(h, rb.axes.up) / rb.r;
                const double q2 = u * u + v * v;
                if (q2 > 1.0) u /= std::sqrt(q2), v /= std::sqrt(q2);
                const double z = std::sqrt(std::max(0.0, 1.0 - u * u - v * v));
                nrm = glm::normalize(u * rb.axes.right + v * rb.axes.up + z * rb.axes.normal);
            } else {
                nrm = glm::dot(rb.axes.normal, dir) > 0.0 ? -rb.axes.normal : rb.axes.normal;
            }
            const bool isotropic = s.shading.model == ShadingModel::isotropic;
            const D3 f = d3(particles.albedo[j]) / (isotropic ? 4.0 * kPi : kPi);

            D3 sum(0.0);
            double fragile = 0.0;
            for (std::size_t i = 0; i < n; ++i) {
                if (i == j) continue;
                const D3 delta = bodies[i].p - x;
                const double d = glm::length(delta);
                double cosTerm = 1.0;
                if (!isotropic) {
                    if (!(d > 0.0)) continue;
                    cosTerm = glm::dot(nrm, delta / d);
                    if (!(cosTerm > 0.0)) continue;
                }
                const double dmin = std::max(double(particles.radius[i]), s.shading.dmin);
                const D3 term = f * d3(particles.emission[i]) * (cosTerm / std::max(d * d, dmin * dmin));
                // V: no other particle's geometry crosses the open segment (x, p_i).
                bool visible = true, unsure = false, firm = false;
                for (std::size_t k = 0; k < n && s.shading.visibility && d > 0.0 && !firm; ++k) {
                    if (k == i || k == j) continue;
                    const Crossing c = cross(k, x, delta);  // t in units of the segment: (0, 1)
                    for (int q = 0; q < c.count; ++q) {
                        const double t = c.t[q];
                        if (t > 0.0 && t < 1.0 && c.inside >= 0.0) visible = false;
                        const bool nearEdge = std::fabs(c.inside) < margin;
                        const bool nearEnd = c.inside >= -margin && (std::fabs(t) < margin || std::fabs(t - 1.0) < margin);
                        if (t > -margin && t < 1.0 + margin && (nearEdge || nearEnd)) unsure = true;
                        else if (t > 0.0 && t < 1.0 && c.inside >= 0.0) firm = true;  // blocked whatever the rounding
                    }
                }
                if (firm) unsure = false;
                if (unsure) fragile += term.x + term.y + term.z;
                if (visible) sum += term;
            }
            img.Lr[px] = sum;
            img.grazing[px] = grazing || fragile > 1e-4 * (sum.x + sum.y + sum.z) || (fragile > 0.0 && sum == D3(0.0));
        }
    });
    return img;
}

}  // namespace accretion::test
