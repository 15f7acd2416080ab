// Cameras from the engine: matrices in every convention read back to the
// pose that wrote them, jitter moves the primary rays and the EXR's NDC
// matrix with them, and malformed camera files are refused naming the record.
#include <catch2/catch.hpp>

#include <fstream>
#include <random>

#include <nlohmann/json.hpp>

#include "accretion/core/error.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/io/exr_output.h"
#include "support/test_scenes.h"

using namespace accretion;
using Catch::Matchers::Contains;

namespace {

CameraPose somePose() {
    CameraPose p = CameraPose::lookAt(Vec3(3.0f, 7.0f, 17.0f), Vec3(0.5f, -1.0f, 0.25f), Vec3(0.0f, 1.0f, 0.0f), 38.0);
    return p;
}

std::string refusal(const CameraSettings& s) {
    try {
        CameraTrack t(s);
        (void)t.pose(0);
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}

}  // namespace

TEST_CASE("camera matrices of every convention read back to the pose that wrote them", "[camera][file]") {
    const char* preset = GENERATE("opengl", "vulkan", "d3d");
    CameraConvention conv;
    REQUIRE(CameraConvention::preset(preset, conv));
    CameraPose pose = somePose();
    pose.jitterX = 0.25;
    pose.jitterY = -0.375;
    Mat4 V, P;
    matricesFromPose(pose, conv, 320, 180, V, P);
    const CameraPose back = poseFromMatrices(V, P, conv, 320, 180, "test");
    INFO(preset);
    // The screen's axes come out as they went in, bit for bit; the eye and
    // the jitter through a little arithmetic.
    CHECK(back.right == pose.right);
    CHECK(back.up == pose.up);
    CHECK(back.forward == pose.forward);
    CHECK(back.tanHalfFov == pose.tanHalfFov);
    CHECK(glm::length(back.eye - pose.eye) < 1e-12);
    CHECK(back.jitterX == Approx(0.25).margin(1e-12));
    CHECK(back.jitterY == Approx(-0.375).margin(1e-12));
}

TEST_CASE("a jittered camera samples at its offset, and projects its samples to pixel centres", "[camera][jitter]") {
    CameraPose pose = somePose();
    const Camera plain = Camera::fromPose(pose, 64, 48);
    pose.jitterX = 0.3;
    pose.jitterY = -0.2;
    const Camera jittered = Camera::fromPose(pose, 64, 48);
    for (std::uint32_t y : {0u, 17u, 47u})
        for (std::uint32_t x : {0u, 31u, 63u}) {
            // The jittered ray through pixel (x, y) is the plain camera's ray
            // through the point (x + 0.5 + 0.3, y + 0.5 - 0.2).
            const double aspect = 64.0 / 48.0;
            const double sx = ((x + 0.8) / 64.0 * 2.0 - 1.0) * plain.tanHalfFovD * aspect;
            const double sy = (1.0 - (y + 0.3) / 48.0 * 2.0) * plain.tanHalfFovD;
            const DVec3 expected = glm::normalize(plain.forwardD + sx * plain.rightD + sy * plain.upD);
            CHECK(glm::length(jittered.pixelRay(x, y) - expected) < 1e-15);
            const Vec3 p = jittered.position + 12.0f * jittered.pixelDirection(x, y);
            float px, py, depth;
            REQUIRE(jittered.project(p, px, py, depth));
            CHECK(px == Approx(x + 0.5f).margin(2e-3));
            CHECK(py == Approx(y + 0.5f).margin(2e-3));
            // The EXR's worldToNDC (row vectors) puts the sample where the pixel is.
            const ExrCameraMatrices m = exrCameraMatrices(pose, 64, 48);
            const DVec3 w = DVec3(jittered.position) + 12.0 * jittered.pixelRay(x, y);
            double ndc[4] = {};
            for (int c = 0; c < 4; ++c)
                ndc[c] = w.x * m.worldToNDC[std::size_t(c)] + w.y * m.worldToNDC[std::size_t(4 + c)] +
                         w.z * m.worldToNDC[std::size_t(8 + c)] + m.worldToNDC[std::size_t(12 + c)];
            CHECK(ndc[0] / ndc[3] == Approx((x + 0.5) / 64.0).margin(1e-5));
            CHECK(ndc[1] / ndc[3] == Approx((y + 0.5) / 48.0).margin(1e-5));
            // worldToCamera: z is the distance along the view direction.
            double cam[3] = {};
            for (int c = 0; c < 3; ++c)
                cam[c] = w.x * m.worldToCamera[std::size_t(c)] + w.y * m.worldToCamera[std::size_t(4 + c)] +
                         w.z * m.worldToCamera[std::size_t(8 + c)] + m.worldToCamera[std::size_t(12 + c)];
            CHECK(cam[2] == Approx(12.0 * glm::dot(jittered.pixelRay(x, y), jittered.forwardD)).epsilon(1e-5));
        }
}

TEST_CASE("camera files: JSON and CSV, poses and matrices, errors naming the record", "[camera][file]") {
    const auto dir = accretion::test::scratchDir("camera_files");
    CameraSettings s;
    s.width = 320;
    s.height = 180;
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name) << text;
        s.file = (dir / name).string();
    };
    // A look-at record equals the same pose from the scene's settings.
    write("pose.json", R"({"frames": [{"frame": 0, "eye": [3, 7, 17], "look_at": [0.5, -1, 0.25], "up": [0, 1, 0], "fov": 38}]})");
    const CameraPose fromFile = CameraTrack(s).pose(0);
    const CameraPose expected = somePose();
    CHECK(fromFile.forward == expected.forward);
    CHECK(fromFile.eye == expected.eye);
    // CSV with a jitter in NDC: 0.5 px = 1/320 of NDC's width 2.
    write("c.csv", "# convention = opengl\n# jitter_units = ndc\nframe,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z,"
                   "up_x,up_y,up_z,fov,jitter_x,jitter_y\n4,3,7,17,0.5,-1,0.25,0,1,0,38,0.003125,0\n");
    CHECK(CameraTrack(s).pose(4).jitterX == Approx(0.5));
    // The units in any case, as a hand-written CSV puts them; after a byte-order mark.
    write("upper.csv", "\xEF\xBB\xBF# jitter_units = NDC\nframe,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z,"
                       "up_x,up_y,up_z,fov,jitter_x,jitter_y\n4,3,7,17,0.5,-1,0.25,0,1,0,38,0.003125,0\n");
    CHECK(CameraTrack(s).pose(4).jitterX == Approx(0.5));
    CHECK_THAT(refusal(s), Contains("no camera for frame 0 (the file holds frames 4..4)"));

    write("scaled.json", R"({"frames": [{"frame": 0, "view": [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
        "projection": [1,0,0,0, 0,1.7778,0,0, 0,0,-1,-1, 0,0,-0.02,0]}]})");
    CHECK_THAT(refusal(s), Contains("frames[0] (frame 0): the view matrix is not a rigid transform"));
    write("aspect.json", R"({"frames": [{"frame": 0, "view": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
        "projection": [1,0,0,0, 0,1,0,0, 0,0,-1,-1, 0,0,-0.02,0]}]})");
    CHECK_THAT(refusal(s), Contains("aspect ratio is 1, the image's 320x180 is 1.77778"));
    write("hand.json", R"({"convention": "d3d", "frames": [{"frame": 0, "view": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1],
        "projection": [1,0,0,0, 0,1.7777777777777777,0,0, 0,0,-1,-1, 0,0,-0.02,0]}]})");
    CHECK_THAT(refusal(s), Contains("divides by -z, but the convention is left-handed"));
    write("twice.json", R"({"frames": [{"frame": 0, "eye": [0,0,5], "look_at": [0,0,0]}, {"frame": 0, "eye": [0,0,6], "look_at": [0,0,0]}]})");
    CHECK_THAT(refusal(s), Contains("frames[1] (frame 0): frame 0 given twice"));
    write("key.json", R"({"frames": [{"frame": 0, "eye": [0,0,5], "look_at": [0,0,0], "fovy": 40}]})");
    CHECK_THAT(refusal(s), Contains("frames[0]: fovy: unknown key"));
    write("jit.json", R"({"frames": [{"frame": 0, "eye": [0,0,5], "look_at": [0,0,0], "jitter": [3, 0]}]})");
    CHECK_THAT(refusal(s), Contains("outside the pixel"));
    write("conv.json", R"({"convention": "directx", "frames": []})");
    CHECK_THAT(refusal(s), Contains("convention \"directx\": expected opengl, vulkan, d3d"));
    write("bad.csv", "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z\n0,1\n");
    CHECK_THAT(refusal(s), Contains("bad.csv:2: 2 values, the header names 7"));
    write("half.csv", "# convention = d3d\nframe,eye_x,eye_y,eye_z\n0,1,2,3\n");
    CHECK_THAT(refusal(s), Contains("half.csv:2: give either eye_x..z and look_at_x..z"));
    write("column.csv", "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z,fovy\n0,0,0,5,0,0,0,40\n");
    CHECK_THAT(refusal(s), Contains("column.csv:1: unknown column 'fovy'"));
    write("fov.csv", "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z,fov\n0,0,0,5,0,0,0,0\n");
    CHECK_THAT(refusal(s), Contains("fov.csv:2 (frame 0): fov: expected degrees in (0, 179), got 0"));
}

namespace {

using M4 = std::array<std::array<double, 4>, 4>;

/// gluLookAt and gluPerspective as their manual defines them (column
/// vectors, m[row][col]).
M4 glLookAt(DVec3 eye, DVec3 center, DVec3 up) {
    const DVec3 f = glm::normalize(center - eye), s = glm::normalize(glm::cross(f, up)), u = glm::cross(s, f);
    return {{{s.x, s.y, s.z, -glm::dot(s, eye)}, {u.x, u.y, u.z, -glm::dot(u, eye)}, {-f.x, -f.y, -f.z, glm::dot(f, eye)},
             {0, 0, 0, 1}}};
}
M4 glPerspective(double fovyDeg, double aspect, double n, double far) {
    const double f = 1.0 / std::tan(fovyDeg * M_PI / 360.0);
    return {{{f / aspect, 0, 0, 0}, {0, f, 0, 0}, {0, 0, (far + n) / (n - far), 2 * far * n / (n - far)}, {0, 0, -1, 0}}};
}
/// XMMatrixLookAtLH and XMMatrixPerspectiveFovLH as DirectXMath documents
/// them (row vectors: p' = p M, m[row][col]).
M4 dxLookAtLH(DVec3 eye, DVec3 at, DVec3 up) {
    const DVec3 z = glm::normalize(at - eye), x = glm::normalize(glm::cross(up, z)), y = glm::cross(z, x);
    return {{{x.x, y.x, z.x, 0}, {x.y, y.y, z.y, 0}, {x.z, y.z, z.z, 0}, {-glm::dot(x, eye), -glm::dot(y, eye), -glm::dot(z, eye), 1}}};
}
M4 dxPerspectiveFovLH(double fovyDeg, double aspect, double zn, double zf) {
    const double h = 1.0 / std::tan(fovyDeg * M_PI / 360.0), w = h / aspect;
    return {{{w, 0, 0, 0}, {0, h, 0, 0}, {0, 0, zf / (zf - zn), 1}, {0, 0, -zn * zf / (zf - zn), 0}}};
}

std::array<double, 4> columnTimes(const M4& m, const std::array<double, 4>& v) {
    std::array<double, 4> r{};
    for (int i = 0; i < 4; ++i)
        for (int k = 0; k < 4; ++k) r[i] += m[i][k] * v[k];
    return r;
}
std::array<double, 4> rowTimes(const std::array<double, 4>& v, const M4& m) {
    std::array<double, 4> r{};
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < 4; ++i) r[k] += v[i] * m[i][k];
    return r;
}

/// The 16 numbers as a file stores them: rows one after the other, or columns.
std::vector<double> stored(const M4& m, bool rowMajor) {
    std::vector<double> v;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) v.push_back(rowMajor ? m[a][b] : m[b][a]);
    return v;
}

}  // namespace

TEST_CASE("engine matrices from the APIs' own formulas project every point where the engine draws it",
          "[camera][file][oracle]") {
    // An independent check of the reader: the matrices are built here from
    // the formulas of gluLookAt/gluPerspective and DirectXMath's LookAtLH/
    // PerspectiveFovLH, the engine's pixel of each point computed by its own
    // clip, divide and viewport; accretion's camera must put it there.
    const auto dir = accretion::test::scratchDir("camera_oracle");
    const std::uint32_t W = 160, H = 90;
    const DVec3 eye(3.0, 7.0, 17.0), at(0.5, -1.0, 0.25), up(0.0, 1.0, 0.0);
    const double fov = 38.0, jx = 0.25, jy = -0.125;  // jitter of the engine's samples, pixels
    const char* api = GENERATE("opengl", "vulkan", "d3d");
    // The engine's camera as its matrices, or as the eye/look_at it made them
    // from (a left-handed engine's look-at is the mirror of a right-handed one's).
    const bool pose = GENERATE(false, true);
    INFO(api << (pose ? ", eye/look_at record" : ", matrices"));
    const bool dx = std::string(api) == "d3d", vk = std::string(api) == "vulkan";
    M4 V, P;
    if (dx) {
        V = dxLookAtLH(eye, at, up);
        P = dxPerspectiveFovLH(fov, double(W) / H, 0.1, 1000.0);
        // TAA: the projection shifted so that pixel centres sample at +j.
        P[2][0] += -2.0 * jx / W;
        P[2][1] += 2.0 * jy / H;
    } else {
        V = glLookAt(eye, at, up);
        P = glPerspective(fov, double(W) / H, 0.1, 1000.0);
        if (vk) P[1][1] = -P[1][1];  // Vulkan: NDC y points down
        P[0][2] += 2.0 * jx / W;     // w = -z: the offset enters with the sign flipped
        P[1][2] += (vk ? 2.0 : -2.0) * jy / H;
    }
    nlohmann::json doc = {{"convention", api},
                          {"frames", {{{"frame", 0}, {"view", stored(V, dx)}, {"projection", stored(P, dx)}}}}};
    if (pose)
        doc["frames"][0] = {{"frame", 0}, {"eye", {eye.x, eye.y, eye.z}}, {"look_at", {at.x, at.y, at.z}},
                            {"up", {up.x, up.y, up.z}}, {"fov", fov}, {"jitter", {jx, jy}}};
    std::ofstream(dir / "cams.json") << doc.dump();
    CameraSettings s;
    s.width = W;
    s.height = H;
    s.file = (dir / "cams.json").string();
    const Camera cam = CameraTrack(s).at(0);
    CHECK(cam.sampleXD - 0.5 == Approx(jx).margin(1e-12));
    CHECK(cam.sampleYD - 0.5 == Approx(jy).margin(1e-12));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-4.0, 4.0);
    for (int k = 0; k < 50; ++k) {
        const DVec3 p = at + DVec3(u(rng), u(rng), u(rng));
        const std::array<double, 4> h = {p.x, p.y, p.z, 1.0};
        const std::array<double, 4> clip = dx ? rowTimes(rowTimes(h, V), P) : columnTimes(P, columnTimes(V, h));
        const double nx = clip[0] / clip[3], ny = clip[1] / clip[3];
        const double ex = (nx + 1.0) * 0.5 * W, ey = (vk ? (1.0 + ny) : (1.0 - ny)) * 0.5 * H;
        float px, py, depth;
        REQUIRE(cam.project(Vec3(p), px, py, depth));
        CHECK(px == Approx(ex).margin(2e-3));
        CHECK(py == Approx(ey).margin(2e-3));
    }
}
