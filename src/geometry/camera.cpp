#include "accretion/geometry/camera.h"

#include <cmath>

namespace accretion {

CameraPose CameraPose::lookAt(const Vec3& eye, const Vec3& target, const Vec3& upHint, double fovDegrees) {
    return lookAt(DVec3(eye), DVec3(target), DVec3(upHint), fovDegrees);
}

CameraPose CameraPose::lookAt(const DVec3& eye, const DVec3& target, const DVec3& upHint, double fovDegrees) {
    CameraPose p;
    p.eye = eye;
    p.forward = glm::normalize(target - eye);
    p.right = glm::normalize(glm::cross(p.forward, upHint));
    p.up = glm::cross(p.right, p.forward);
    p.tanHalfFov = std::tan(0.5 * fovDegrees * M_PI / 180.0);
    return p;
}

Camera Camera::fromPose(const CameraPose& pose, std::uint32_t width, std::uint32_t height) {
    Camera c;
    c.position = Vec3(pose.eye);
    // The basis in double; the float one (Embree's rays) is its rounding.
    c.forwardD = pose.forward;
    c.rightD = pose.right;
    c.upD = pose.up;
    c.tanHalfFovD = pose.tanHalfFov;
    c.forward = Vec3(c.forwardD);
    c.right = Vec3(c.rightD);
    c.up = Vec3(c.upD);
    c.tanHalfFov = float(c.tanHalfFovD);
    c.sampleXD = 0.5 + pose.jitterX;
    c.sampleYD = 0.5 + pose.jitterY;
    c.sampleX = float(c.sampleXD);
    c.sampleY = float(c.sampleYD);
    c.width = c.imageWidth = width;
    c.height = c.imageHeight = height;
    return c;
}

Camera Camera::lookAt(const Vec3& eye, const Vec3& target, const Vec3& upHint, double fovDegrees,
                      std::uint32_t width, std::uint32_t height) {
    return fromPose(CameraPose::lookAt(eye, target, upHint, fovDegrees), width, height);
}

CameraPose CameraPose::atFrame(const CameraSettings& s, std::uint32_t frame) {
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
    return lookAt(eye, target, s.up, s.fov);
}

Camera Camera::atFrame(const CameraSettings& s, std::uint32_t frame) {
    return fromPose(CameraPose::atFrame(s, frame), s.width, s.height);
}

}  // namespace accretion
