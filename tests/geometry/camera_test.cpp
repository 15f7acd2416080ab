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
