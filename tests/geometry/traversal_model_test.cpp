// The traversal model's nodes visited, by closed form (a ray through a row
// of boxes that hits none of them visits every inner node; a ray missing the
// root visits none), and its hits against brute force over every box, built
// and refitted.
#include <catch2/catch.hpp>

#include <limits>
#include <optional>
#include <random>

#include "accretion/geometry/embree_device.h"
#include "accretion/geometry/traversal_model.h"

using namespace accretion;

namespace {

RTCBounds box(const Vec3& centre, float half) {
    return {centre.x - half, centre.y - half, centre.z - half, 0.0f, centre.x + half, centre.y + half, centre.z + half, 0.0f};
}

/// Where o + t d enters b within [tnear, tfar] (a box is its own primitive here).
std::optional<float> entry(const RTCBounds& b, const Vec3& o, const Vec3& d, float tnear, float tfar) {
    const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
    double t0 = tnear, t1 = tfar;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0f) {
            if (o[k] < lo[k] || o[k] > hi[k]) return std::nullopt;
            continue;
        }
        double a = (double(lo[k]) - o[k]) / d[k], c = (double(hi[k]) - o[k]) / d[k];
        if (a > c) std::swap(a, c);
        t0 = std::max(t0, a);
        t1 = std::min(t1, c);
    }
    if (t0 > t1) return std::nullopt;
    return float(t0);
}

/// The nearest box o + t d enters, by brute force.
std::optional<std::pair<std::uint32_t, float>> nearestBox(const std::vector<RTCBounds>& boxes, const Vec3& o, const Vec3& d) {
    std::optional<std::pair<std::uint32_t, float>> best;
    for (std::uint32_t i = 0; i < boxes.size(); ++i)
        if (const auto t = entry(boxes[i], o, d, 0.0f, std::numeric_limits<float>::infinity()); t && (!best || *t < best->second))
            best = std::pair{i, *t};
    return best;
}

}  // namespace

TEST_CASE("a ray through a row of boxes it never hits visits every inner node, a ray beside it none", "[traversal]") {
    EmbreeDevice device;
    for (const std::uint32_t n : {1u, 2u, 3u, 17u, 256u, 1000u}) {
        std::vector<RTCBounds> row;
        for (std::uint32_t i = 0; i < n; ++i) row.push_back(box(Vec3(2.0f * float(i), 0.0f, 0.0f), 0.5f));
        TraversalModel model;
        model.build(device.get(), row);
        INFO("boxes " << n);
        REQUIRE(model.primitives() == n);
        REQUIRE(model.nodes() == n - 1);
        std::uint32_t tested = 0;
        const auto none = [&](std::uint32_t, float, float, float&) { ++tested; return false; };
        const float inf = std::numeric_limits<float>::infinity();
        // Along the row: every box entered, every leaf tested, nothing culled.
        CHECK(model.closestHit(Vec3(-5.0f, 0.1f, 0.2f), Vec3(1.0f, 0.0f, 0.0f), 0.0f, inf, none) == n - 1);
        CHECK(tested == n);
        tested = 0;
        CHECK(model.anyHit(Vec3(-5.0f, 0.1f, 0.2f), Vec3(1.0f, 0.0f, 0.0f), 0.0f, inf, none) == n - 1);
        CHECK(tested == n);
        // Beside it, and along it but short of the first box: the root's box is missed.
        tested = 0;
        CHECK(model.closestHit(Vec3(-5.0f, 3.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f), 0.0f, inf, none) == 0);
        CHECK(model.anyHit(Vec3(-5.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 0.0f), 0.0f, 4.0f, none) == 0);
        CHECK(tested == 0);
    }
}

TEST_CASE("the traversal model finds brute force's nearest box, built and refitted", "[traversal]") {
    EmbreeDevice device;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-10.0f, 10.0f), size(0.05f, 0.6f);
    std::vector<RTCBounds> boxes;
    std::vector<Vec3> centres;
    for (int i = 0; i < 3000; ++i) {
        centres.emplace_back(u(rng), u(rng), 0.2f * u(rng));  // a flattened cloud, as the disk and the cluster are
        boxes.push_back(box(centres.back(), size(rng)));
    }
    TraversalModel model;
    model.build(device.get(), boxes);
    const auto check = [&](const char* what) {
        std::uint64_t visits = 0, hits = 0;
        for (int r = 0; r < 400; ++r) {
            const Vec3 o(u(rng), u(rng), 15.0f);
            const Vec3 d = glm::normalize(Vec3(u(rng), u(rng), -15.0f) - o);
            std::optional<std::uint32_t> found;
            const auto hitBox = [&](std::uint32_t i, float tnear, float tfar, float& t) {
                const auto e = entry(boxes[i], o, d, tnear, tfar);
                if (e) t = *e, found = i;
                return e.has_value();
            };
            visits += model.closestHit(o, d, 0.0f, std::numeric_limits<float>::infinity(), hitBox);
            const auto expected = nearestBox(boxes, o, d);
            INFO(what << ", ray " << r);
            REQUIRE(found.has_value() == expected.has_value());
            if (expected) REQUIRE(*found == expected->first);
            hits += expected.has_value();
            // A shadow ray finds a blocker exactly when one is there.
            found.reset();
            model.anyHit(o, d, 0.0f, std::numeric_limits<float>::infinity(), hitBox);
            REQUIRE(found.has_value() == expected.has_value());
        }
        CHECK(hits > 40);             // the rays meet boxes ...
        CHECK(visits > 400);          // ... through the tree, not only its root
    };
    check("built");
    // Moved, the same topology: refitted boxes still contain their primitives.
    for (std::size_t i = 0; i < boxes.size(); ++i) {
        centres[i] += Vec3(0.8f * std::sin(float(i)), 0.8f * std::cos(float(i)), 0.0f);
        boxes[i] = box(centres[i], 0.5f * (boxes[i].upper_x - boxes[i].lower_x));
    }
    model.refit(boxes);
    check("refitted");
}
