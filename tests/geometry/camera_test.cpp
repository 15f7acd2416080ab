#include <catch2/catch.hpp>

#include "accretion/geometry/camera.h"

using namespace accretion;

TEST_CASE("pinhole camera: centre ray, corners, orthonormal frame", "[camera]") {
    CameraSettings s;
    s.position = Vec3(0.0f, 0.0f, 5.0f);
    s.look_at = Vec3(0.0f);
    s.fov = 90.0;
    s.width = 3;
    s.height = 3;
    const Camera c = Camera::atFrame(s, 0);
    REQUIRE(glm::length(c.pixelDirection(1, 1) - Vec3(0.0f, 0.0f, -1.0f)) < 1e-6f);
    // fov 90: the top row's centre is at tan(45) * (1 - 1/3) = 2/3 above the axis.
    const Vec3 top = c.pixelDirection(1, 0);
    REQUIRE(top.y / -top.z == Approx(2.0 / 3.0).epsilon(1e-5));
    REQUIRE(c.pixelDirection(0, 1).x < 0.0f);  // x grows to the right
    REQUIRE(glm::dot(c.right, c.up) == Approx(0.0f).margin(1e-6));
    REQUIRE(glm::dot(c.right, c.forward) == Approx(0.0f).margin(1e-6));
}

TEST_CASE("camera paths: orbit about the y axis and linear interpolation", "[camera]") {
    CameraSettings s;
    s.position = Vec3(0.0f, 2.0f, 10.0f);
    s.look_at = Vec3(0.0f);
    s.path = CameraPath::orbit;
    s.orbit_speed = 30.0;
    const Camera c = Camera::atFrame(s, 3);  // 90 degrees
    REQUIRE(c.position.x == Approx(10.0f).epsilon(1e-5));
    REQUIRE(c.position.y == Approx(2.0f));
    REQUIRE(c.position.z == Approx(0.0f).margin(1e-5));
    s.path = CameraPath::linear;
    s.end_position = Vec3(4.0f, 2.0f, 10.0f);
    s.path_frames = 8;
    REQUIRE(Camera::atFrame(s, 4).position.x == Approx(2.0f));
    REQUIRE(Camera::atFrame(s, 0).position == s.position);
}

TEST_CASE("a window camera's pixels are the image's, ray for ray and projection for projection", "[camera][window]") {
    CameraSettings s;
    s.position = Vec3(0.3f, 2.0f, 7.0f);
    s.look_at = Vec3(0.1f, 0.0f, -0.2f);
    s.fov = 47.0;
    s.width = 200;
    s.height = 120;
    const Camera image = Camera::atFrame(s, 0);
    const Camera window = image.window(40, 24, 72, 56);
    CHECK(window.isWindow());
    CHECK_FALSE(image.isWindow());
    CHECK(window.width == 72);
    CHECK(window.imageWidth == 200);
    for (std::uint32_t y = 0; y < window.height; y += 5)
        for (std::uint32_t x = 0; x < window.width; x += 3) {
            INFO(x << ", " << y);
            REQUIRE(window.pixelDirection(x, y) == image.pixelDirection(x + 40, y + 24));  // bit for bit
            REQUIRE(window.pixelRay(x, y) == image.pixelRay(x + 40, y + 24));
            // The window's pixel centre projects to the window's pixel coordinates.
            const Vec3 p = window.position + 3.0f * window.pixelDirection(x, y);
            float wx, wy, wd, ix, iy, id;
            REQUIRE(window.project(p, wx, wy, wd));
            REQUIRE(image.project(p, ix, iy, id));
            CHECK(wx == Approx(ix - 40.0f).margin(1e-3));
            CHECK(wy == Approx(iy - 24.0f).margin(1e-3));
            CHECK(wx == Approx(float(x) + 0.5f).margin(2e-3));
            CHECK(wd == id);
        }
    // A window of a window is the image's window at the summed offset.
    CHECK(window.window(8, 8, 16, 16).pixelDirection(1, 2) == image.pixelDirection(49, 34));
}
