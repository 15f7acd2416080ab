#include "accretion/geometry/camera.h"

#include <cmath>

namespace accretion {

Camera Camera::lookAt(const Vec3& eye, const Vec3& target, const Vec3& upHint, double fovDegrees,
                      std::uint32_t width, std::uint32_t height) {
    Camera c;
    c.position = eye;
    // The basis in double; the float one (Embree's rays) is its rounding.
    c.forwardD = glm::normalize(DVec3(target) - DVec3(eye));
    c.rightD = glm::normalize(glm::cross(c.forwardD, DVec3(upHint)));
    c.upD = glm::cross(c.rightD, c.forwardD);
    c.tanHalfFovD = std::tan(0.5 * fovDegrees * M_PI / 180.0);
    c.forward = Vec3(c.forwardD);
    c.right = Vec3(c.rightD);
    c.up = Vec3(c.upD);
    c.tanHalfFov = float(c.tanHalfFovD);
    c.width = width;
    c.height = height;
    return c;
}

Camera Camera::atFrame(const CameraSettings& s, std::uint32_t frame) {
    Vec3 eye = s.position, target = s.look_at;
    switch (s.path) {
    case CameraPath::static_pose: break;
    case CameraPath::orbit: {
        const double a = double(frame) * s.orbit_speed * M_PI / 180.0;
        const Vec3 d = eye - target;
        const float c = float(std::cos(a)), sn = float(std::sin(a));
        eye = target + Vec3(c * d.x + sn * d.z, d.y, -sn * d.x + c * d.z);
        break;
    }
    case CameraPath::linear: {
        const float t = float(frame) / float(s.path_frames);
        eye = s.position + t * (s.end_position - s.position);
        target = s.look_at + t * (s.end_look_at - s.look_at);
        break;
    }
    }
    return lookAt(eye, target, s.up, s.fov, s.width, s.height);
}

}  // namespace accretion
