#pragma once
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// A frame's camera as the engine states it, in double: the eye, the
/// screen's axes in world space (right = image +x, up = image +y, forward =
/// the view direction; orthonormal), tan of half the vertical field of view,
/// and the sub-pixel jitter of the frame's samples (TAA): the offset of the
/// sample from the pixel centre, in pixels, +x right, +y down.
struct CameraPose {
    DVec3 eye{0.0};
    DVec3 forward{0.0, 0.0, -1.0}, right{1.0, 0.0, 0.0}, up{0.0, 1.0, 0.0};
    double tanHalfFov = 1.0;
    double jitterX = 0.0, jitterY = 0.0;

    /// The pose of a look-at camera (what the scene's paths give).
    static CameraPose lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, double fovDegrees);
    static CameraPose lookAt(const DVec3& eye, const DVec3& target, const DVec3& up, double fovDegrees);
    /// The pose of a frame along the scene's path (static, orbit, linear).
    static CameraPose atFrame(const CameraSettings& s, std::uint32_t frame);
};

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
    /// Where in the pixel the frame samples: its centre (0.5, 0.5) plus the
    /// pose's jitter; float and double as the rays use them.
    float sampleX = 0.5f, sampleY = 0.5f;
    double sampleXD = 0.5, sampleYD = 0.5;
    /// A window of a larger image (window()): that image's size, and where
    /// this camera's pixel (0, 0) lies in it. The whole image by default
    /// (fromPose): the offsets are 0 and the image is width x height.
    std::uint32_t imageWidth = 0, imageHeight = 0;
    float pixelX0 = 0.0f, pixelY0 = 0.0f;
    double pixelX0D = 0.0, pixelY0D = 0.0;

    /// The camera of a frame along the scene's path.
    static Camera atFrame(const CameraSettings& s, std::uint32_t frame);
    static Camera lookAt(const Vec3& eye, const Vec3& target, const Vec3& up, double fovDegrees,
                         std::uint32_t width, std::uint32_t height);
    /// The camera of a pose: its float basis is the rounding of the double one.
    static Camera fromPose(const CameraPose& pose, std::uint32_t width, std::uint32_t height);

    /// The camera of the w x h window at (x0, y0) of this camera's image: its
    /// pixel (x, y) is the image's (x0 + x, y0 + y), the same ray bit for bit
    /// (integers below 2^24 add exactly), and project() gives window pixels.
    /// A renderer that runs on the window's pixels alone (restir.crop_margin)
    /// renders that part of the image.
    Camera window(std::uint32_t x0, std::uint32_t y0, std::uint32_t w, std::uint32_t h) const {
        Camera c = *this;
        c.width = w;
        c.height = h;
        c.pixelX0 = pixelX0 + float(x0);
        c.pixelY0 = pixelY0 + float(y0);
        c.pixelX0D = pixelX0D + double(x0);
        c.pixelY0D = pixelY0D + double(y0);
        return c;
    }
    bool isWindow() const { return width != imageWidth || height != imageHeight; }

    /// Unit direction of the ray through pixel (x, y)'s sample position (the
    /// centre, jittered); y = 0 is the top row.
    ACC_HD Vec3 pixelDirection(std::uint32_t x, std::uint32_t y) const {
        const float aspect = float(imageWidth) / float(imageHeight);
        const float sx = ((float(x) + pixelX0 + sampleX) / float(imageWidth) * 2.0f - 1.0f) * tanHalfFov * aspect;
        const float sy = (1.0f - (float(y) + pixelY0 + sampleY) / float(imageHeight) * 2.0f) * tanHalfFov;
        return glm::normalize(forward + sx * right + sy * up);
    }

    /// The same ray in double: what primary hits are refined along.
    ACC_HD DVec3 pixelRay(std::uint32_t x, std::uint32_t y) const {
        const double aspect = double(imageWidth) / double(imageHeight);
        const double sx = ((double(x) + pixelX0D + sampleXD) / double(imageWidth) * 2.0 - 1.0) * tanHalfFovD * aspect;
        const double sy = (1.0 - (double(y) + pixelY0D + sampleYD) / double(imageHeight) * 2.0) * tanHalfFovD;
        return glm::normalize(forwardD + sx * rightD + sy * upD);
    }

    /// This camera in coordinates whose origin is at `origin` (the renderer
    /// works relative to the frame's camera: docs/MODEL.md section 3, precision).
    Camera rebased(const Vec3& origin) const {
        Camera c = *this;
        c.position = position - origin;
        return c;
    }

    /// Continuous pixel coordinates (of the window, for a window camera; the frame's sample positions at +0.5, so
    /// that a jittered frame's own samples project to pixel centres) and
    /// camera-space depth of a world point; false when it is not in front of
    /// the camera.
    ACC_HD bool project(const Vec3& p, float& px, float& py, float& depth) const {
        const Vec3 d = p - position;
        depth = glm::dot(d, forward);
        if (!(depth > 0.0f)) return false;
        const float aspect = float(imageWidth) / float(imageHeight);
        const float sx = glm::dot(d, right) / (depth * tanHalfFov * aspect);
        const float sy = glm::dot(d, up) / (depth * tanHalfFov);
        px = (sx + 1.0f) * 0.5f * float(imageWidth) - (sampleX - 0.5f) - pixelX0;
        py = (1.0f - sy) * 0.5f * float(imageHeight) - (sampleY - 0.5f) - pixelY0;
        return true;
    }
};

}  // namespace accretion
