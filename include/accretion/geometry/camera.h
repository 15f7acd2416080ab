#pragma once
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// A pinhole camera pose of one frame.
struct Camera {
    Vec3 position;       ///< eye
    Vec3 forward;        ///< unit view direction
    Vec3 right;          ///< unit, image +x
    Vec3 up;             ///< unit, image +y
    float tanHalfFov;    ///< tan(vertical fov / 2)
    std::uint32_t width, height;
    DVec3 forwardD, rightD, upD;  ///< the same basis computed in double (hit points are refined with it)
    double tanHalfFovD;

    /// The camera of a frame along the scene's path.
    static Camera atFrame(const CameraSettings& s, std::uint32_t frame);
    static Camera lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, double fovDegrees,
                         std::uint32_t width, std::uint32_t height);

    /// Unit direction of the ray through the centre of pixel (x, y); y = 0 is the top row.
    Vec3 pixelDirection(std::uint32_t x, std::uint32_t y) const {
        const float aspect = float(width) / float(height);
        const float sx = ((float(x) + 0.5f) / float(width) * 2.0f - 1.0f) * tanHalfFov * aspect;
        const float sy = (1.0f - (float(y) + 0.5f) / float(height) * 2.0f) * tanHalfFov;
        return glm::normalize(forward + sx * right + sy * up);
    }

    /// The same ray in double: what primary hits are refined along.
    DVec3 pixelRay(std::uint32_t x, std::uint32_t y) const {
        const double aspect = double(width) / double(height);
        const double sx = ((double(x) + 0.5) / double(width) * 2.0 - 1.0) * tanHalfFovD * aspect;
        const double sy = (1.0 - (double(y) + 0.5) / double(height) * 2.0) * tanHalfFovD;
        return glm::normalize(forwardD + sx * rightD + sy * upD);
    }

    /// This camera in coordinates whose origin is at `origin` (the renderer
    /// works relative to the frame's camera: docs/MODEL.md section 3, precision).
    Camera rebased(const Vec3& origin) const {
        Camera c = *this;
        c.position = position - origin;
        return c;
    }

    /// Continuous pixel coordinates (pixel centres at +0.5) and camera-space
    /// depth of a world point; false when it is not in front of the camera.
    bool project(const Vec3& p, float& px, float& py, float& depth) const {
        const Vec3 d = p - position;
        depth = glm::dot(d, forward);
        if (!(depth > 0.0f)) return false;
        const float aspect = float(width) / float(height);
        const float sx = glm::dot(d, right) / (depth * tanHalfFov * aspect);
        const float sy = glm::dot(d, up) / (depth * tanHalfFov);
        px = (sx + 1.0f) * 0.5f * float(width);
        py = (1.0f - sy) * 0.5f * float(height);
        return true;
    }
};

}  // namespace accretion
