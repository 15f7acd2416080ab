// The Embree BVH against brute force: every primary-ray hit and occlusion
// answer must match a direct test of the ray against every particle.
#include <catch2/catch.hpp>

#include <limits>

#include "accretion/geometry/particle_bvh.h"
#include "support/statistics.h"
#include "support/test_scenes.h"
#include "accretion/particles/disk_generator.h"
#include "accretion/geometry/camera.h"

using namespace accretion;

namespace {

/// Calls f(x, y, direction) for the primary ray of every pixel of cam.
template <class F> void forEachPixelRay(const Camera& cam, F&& f) {
    for (std::uint32_t y = 0; y < cam.height; ++y)
        for (std::uint32_t x = 0; x < cam.width; ++x) f(x, y, cam.pixelDirection(x, y));
}

/// Closest hit in [tnear, tfar) by brute force: billboard quads (optionally
/// disc-tested) or spheres (d a unit vector).
float bruteForce(const Particles& p, const std::vector<BillboardFrame>& frames, const GeometrySettings& g, const Vec3& o,
                 const Vec3& d, float tfar, std::uint32_t& hitParticle, float tnear = 0.0f) {
    float best = tfar;
    hitParticle = std::numeric_limits<std::uint32_t>::max();
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        float t;
        if (g.primitive == Primitive::sphere) {
            const Vec3 oc = o - p.position[i];
            const float b = glm::dot(oc, d), c = glm::dot(oc, oc) - p.radius[i] * p.radius[i];
            const float disc = b * b - c;
            if (disc < 0.0f) continue;
            t = -b - std::sqrt(disc);
            if (t < tnear) t = -b + std::sqrt(disc);
        } else {
            const Vec3 n = frames[i].normal();
            const float denom = glm::dot(n, d);
            if (std::fabs(denom) < 1e-12f) continue;
            t = glm::dot(p.position[i] - o, n) / denom;
            const Vec3 q = o + t * d - p.position[i];
            const float a = glm::dot(q, frames[i].right) / p.radius[i], b = glm::dot(q, frames[i].up) / p.radius[i];
            if (std::fabs(a) > 1.0f || std::fabs(b) > 1.0f) continue;
            if (g.alpha == AlphaMode::disc && a * a + b * b > 1.0f) continue;
        }
        if (t >= tnear && t < best) {
            best = t;
            hitParticle = i;
        }
    }
    return best;
}

/// The particles' quad boxes, p -+ r (|right| + |up|), that o + t d, t in
/// [tnear, tfar], overlaps: a slab test per particle, each box widened
/// (slack > 0) or narrowed (< 0) by a relative margin.
std::uint32_t overlappedBoxes(const Particles& p, const ParticleBvh& bvh, const Vec3& o, const Vec3& d, float tnear,
                              float tfar, float slack) {
    std::uint32_t n = 0;
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        const BillboardFrame& f = bvh.frame(i);
        const Vec3 e = p.radius[i] * (glm::abs(f.right) + glm::abs(f.up)) * (1.0f + slack);
        float t0 = tnear, t1 = tfar;
        for (int k = 0; k < 3; ++k) {
            float lo = (p.position[i][k] - e[k] - o[k]) / d[k], hi = (p.position[i][k] + e[k] - o[k]) / d[k];
            if (lo > hi) std::swap(lo, hi);
            t0 = std::max(t0, lo);
            t1 = std::min(t1, hi);
        }
        n += t0 <= t1;
    }
    return n;
}

}  // namespace

TEST_CASE("Embree hits match brute force for every geometry and build policy", "[geometry][bvh][long]") {
    GeometrySettings g;
    g.primitive = GENERATE(Primitive::billboard, Primitive::sphere);
    g.alpha = g.primitive == Primitive::sphere ? AlphaMode::opaque : GENERATE(AlphaMode::opaque, AlphaMode::disc);
    g.orientation = GENERATE(Orientation::view_plane, Orientation::view_point, Orientation::velocity);
    g.build = GENERATE(BuildPolicy::rebuild, BuildPolicy::refit, BuildPolicy::fast_trace);
    // Every GPU layout (the aabbs and instances layouts are box primitives running the billboard intersection).
    g.layout = g.primitive == Primitive::sphere ? AccelLayout::clusters
                                                : GENERATE(AccelLayout::clusters, AccelLayout::instances, AccelLayout::aabbs);
    g.cluster_size = 16;
    INFO(enumName(g.primitive) << " " << enumName(g.alpha) << " " << enumName(g.orientation) << " " << enumName(g.build) << " "
                               << enumName(g.layout));

    // Counting, spheres are box primitives running their own sphere test: brute force checks both.
    GpuSettings gpu;
    gpu.counters = g.primitive == Primitive::sphere && GENERATE(false, true);
    INFO("counting " << gpu.counters);

    auto [ps, cs] = accretion::test::smallView(400, 3.0, 0.1, Vec3(0.0f, 3.0f, 6.0f), 40, 30);
    ps.time_step = 0.2;
    EmbreeDevice device;
    ParticleBvh bvh(device, g, gpu);

    // Refit reuses frame 0's clusters. Under the sanitizers (a seed divisor)
    // two frames, the rebuild and one refit: the brute force over every ray
    // and particle took 13 s there, 4x Release.
    const std::uint32_t frameCount = accretion::test::fullStatisticalPower() ? 3 : 2;
    for (std::uint32_t frame = 0; frame < frameCount; ++frame) {
        const Particles p = generateDisk(ps, frame);
        const Camera cam = Camera::atFrame(cs, frame);
        bvh.build(p, cam);
        REQUIRE(bvh.stats().refitted == (g.build == BuildPolicy::refit && frame > 0));
        std::vector<BillboardFrame> frames(p.size());
        for (std::uint32_t i = 0; i < p.size(); ++i) frames[i] = bvh.frame(i);
        // The frames the brute force reuses are checked on their own: orthonormal,
        // facing the camera as docs/MODEL.md section 2 defines for each mode.
        if (g.primitive == Primitive::billboard)
            for (std::uint32_t i = 0; i < p.size(); ++i) {
                const BillboardFrame& f = frames[i];
                REQUIRE(glm::length(f.right) == Approx(1.0f).epsilon(1e-5));
                REQUIRE(glm::length(f.up) == Approx(1.0f).epsilon(1e-5));
                REQUIRE(glm::dot(f.right, f.up) == Approx(0.0f).margin(1e-5));
                const Vec3 toEye = glm::normalize(cam.position - p.position[i]);
                if (g.orientation == Orientation::view_plane)
                    REQUIRE(glm::dot(f.normal(), -cam.forward) == Approx(1.0f).epsilon(1e-5));
                else
                    REQUIRE(glm::dot(f.normal(), toEye) == Approx(1.0f).epsilon(1e-5));
                if (g.orientation == Orientation::velocity) {  // right along the velocity seen from the eye
                    const Vec3 v = p.velocity[i] - glm::dot(p.velocity[i], toEye) * toEye;
                    REQUIRE(glm::dot(f.right, glm::normalize(v)) == Approx(1.0f).epsilon(1e-4));
                }
            }

        int hits = 0, mismatches = 0;
        forEachPixelRay(cam, [&](std::uint32_t, std::uint32_t, const Vec3& d) {
            std::uint32_t want;
            const float tWant = bruteForce(p, frames, g, cam.position, d, 1e30f, want);
            SurfaceHit hit;
            const bool got = bvh.intersect(cam.position, d, 1e30f, hit);
            if (want == std::numeric_limits<std::uint32_t>::max()) {
                mismatches += got;  // brute force saw nothing
                return;
            }
            ++hits;
            // Equal particle, or (edge/tie cases) an equally close hit.
            if (!got || (hit.particle != want && std::fabs(hit.t - tWant) > 1e-4f * tWant)) ++mismatches;
            // Occlusion of the segment up to just before the closest hit is empty.
            if (bvh.occluded(cam.position, d, 0.0f, tWant * (1.0f - 1e-4f))) ++mismatches;
            if (!bvh.occluded(cam.position, d, 0.0f, tWant * (1.0f + 1e-3f) + 1e-3f)) ++mismatches;
        });
        REQUIRE(hits > 50);
        // Rays grazing a quad edge may legitimately differ by float rounding.
        REQUIRE(mismatches <= 2);
    }
}

TEST_CASE("build stats: clusters, primitives and Embree memory", "[geometry][bvh]") {
    ParticleSettings ps;
    ps.count = 3000;
    const Particles p = generateDisk(ps, 0);
    EmbreeDevice device;
    GeometrySettings g;
    g.cluster_size = 100;
    ParticleBvh bvh(device, g);
    bvh.build(p, Camera::atFrame(CameraSettings{}, 0));
    REQUIRE(bvh.stats().primitives == 6000);
    REQUIRE(bvh.stats().clusters == bvh.clusters().count());
    REQUIRE(bvh.stats().clusters >= 30);
    // At least the vertex and index buffers (4 float3 corners + one quad index, 48 + 16 bytes per billboard).
    REQUIRE(bvh.stats().embreeBytes >= std::int64_t(64 * ps.count));
}

namespace {

/// Clusters whose BLAS bounds the ray o + t d, t in [0, tfar), overlaps (slab
/// test; slack > 0 widens the exit distances, < 0 narrows them).
std::uint32_t overlappedClusters(const ParticleBvh& bvh, const Vec3& o, const Vec3& d, float tfar, float slack = 1e-5f) {
    std::uint32_t n = 0;
    for (std::size_t c = 0; c < bvh.clusters().count(); ++c) {
        const RTCBounds& b = bvh.blasBounds(c);
        const float lo[3] = {b.lower_x, b.lower_y, b.lower_z}, hi[3] = {b.upper_x, b.upper_y, b.upper_z};
        float t0 = 0.0f, t1 = tfar;
        for (int k = 0; k < 3; ++k) {
            const float inv = 1.0f / d[k];
            float a = (lo[k] - o[k]) * inv, bb = (hi[k] - o[k]) * inv;
            if (a > bb) std::swap(a, bb);
            t0 = std::max(t0, a);
            t1 = std::min(t1, bb * (1.0f + slack));
        }
        n += t0 <= t1;
    }
    return n;
}

}  // namespace

TEST_CASE("counting queries: same answers, BLAS entries bounded by the overlapped clusters, any-hits only with alpha",
          "[geometry][bvh][gpu]") {
    GeometrySettings g;
    g.primitive = GENERATE(Primitive::billboard, Primitive::sphere);
    g.alpha = g.primitive == Primitive::sphere ? AlphaMode::opaque : GENERATE(AlphaMode::opaque, AlphaMode::disc);
    g.build = GENERATE(BuildPolicy::rebuild, BuildPolicy::refit);
    g.cluster_size = 16;
    INFO(enumName(g.primitive) << " " << enumName(g.alpha) << " " << enumName(g.build));
    const auto [ps, cs] = accretion::test::smallView(400, 3.0, 0.1, Vec3(0.0f, 3.0f, 6.0f), 40, 30);
    EmbreeDevice device;
    GpuSettings gpu;
    gpu.counters = true;
    ParticleBvh bvh(device, g, gpu);
    for (std::uint32_t frame = 0; frame < 2; ++frame) {
        const Particles p = generateDisk(ps, frame);
        const Camera cam = Camera::atFrame(cs, frame);
        bvh.build(p, cam);
        std::uint64_t entries = 0, anyHits = 0, hits = 0;
        forEachPixelRay(cam, [&](std::uint32_t, std::uint32_t, const Vec3& d) {
            SurfaceHit plain, counted;
            RayCounters rc;
            const bool a = bvh.intersect(cam.position, d, 1e30f, plain);
            const bool b = bvh.intersect(cam.position, d, 1e30f, counted, &rc);
            REQUIRE(a == b);
            if (a) {
                REQUIRE(counted.particle == plain.particle);
                REQUIRE(counted.cluster == plain.cluster);
                REQUIRE(counted.t == plain.t);
                REQUIRE(rc.blasEntries >= 1);
                ++hits;
            }
            // Traversal enters every box that starts before the closest hit
            // (tfar never drops below it), and no box the ray misses.
            REQUIRE(rc.blasEntries <= overlappedClusters(bvh, cam.position, d, 1e30f));
            REQUIRE(rc.blasEntries >= overlappedClusters(bvh, cam.position, d, a ? plain.t * (1.0f - 1e-4f) : 1e30f, -1e-5f));
            if (g.alpha == AlphaMode::opaque) REQUIRE(rc.anyHits == 0);
            REQUIRE(rc.candidates == rc.anyHits);
            entries += rc.blasEntries;
            anyHits += rc.anyHits;
            RayCounters oc;
            const float tfar = a ? plain.t * 1.01f : 1e30f;
            REQUIRE(bvh.occluded(cam.position, d, 0.0f, tfar) == bvh.occluded(cam.position, d, 0.0f, tfar, {}, &oc));
            REQUIRE(oc.blasEntries <= overlappedClusters(bvh, cam.position, d, tfar));
        });
        REQUIRE(hits > 50);
        REQUIRE(entries >= hits);
        if (g.alpha == AlphaMode::disc) REQUIRE(anyHits >= hits);
    }
}

TEST_CASE("the traversal model's nodes: a refit of unmoved particles visits what a build does", "[geometry][bvh][gpu]") {
    // The refit policy keeps the first frame's topology and recomputes its
    // boxes; over the same particles they are the build's boxes, so every
    // ray visits the same nodes, ray by ray. Moved, the refit's topology is
    // the first frame's, which is not the one a build would choose.
    const auto [ps, cs] = accretion::test::smallView(400, 3.0, 0.1, Vec3(0.0f, 3.0f, 6.0f), 40, 30);
    EmbreeDevice device;
    GpuSettings gpu;
    gpu.counters = true;
    GeometrySettings rebuilt, refitted;
    rebuilt.build = BuildPolicy::rebuild;
    refitted.build = BuildPolicy::refit;
    ParticleBvh a(device, rebuilt, gpu), b(device, refitted, gpu);
    const Particles p0 = generateDisk(ps, 0), p5 = generateDisk(ps, 5);
    const Camera cam = Camera::atFrame(cs, 0);
    a.build(p0, cam);
    b.build(p5, cam);  // the refit's topology: frame 5's
    b.build(p0, cam);  // refitted onto frame 0's particles
    REQUIRE(b.stats().refitted);
    std::uint64_t sumA = 0, sumB = 0, differ = 0;
    forEachPixelRay(cam, [&](std::uint32_t, std::uint32_t, const Vec3& d) {
        SurfaceHit ha, hb;
        RayCounters ra, rb;
        REQUIRE(a.intersect(cam.position, d, 1e30f, ha, &ra) == b.intersect(cam.position, d, 1e30f, hb, &rb));
        sumA += ra.nodeVisits;
        sumB += rb.nodeVisits;
        differ += ra.nodeVisits != rb.nodeVisits;
    });
    REQUIRE(sumA > 0);
    REQUIRE(differ > 0);  // another topology, other nodes
    ParticleBvh c(device, refitted, gpu);
    c.build(p0, cam);
    c.build(p0, cam);  // refitted onto the particles it was built on
    REQUIRE(c.stats().refitted);
    std::uint64_t sumC = 0;
    forEachPixelRay(cam, [&](std::uint32_t, std::uint32_t, const Vec3& d) {
        SurfaceHit ha, hc;
        RayCounters ra, rc;
        a.intersect(cam.position, d, 1e30f, ha, &ra);
        c.intersect(cam.position, d, 1e30f, hc, &rc);
        REQUIRE(rc.nodeVisits == ra.nodeVisits);
        sumC += rc.nodeVisits;
    });
    REQUIRE(sumC == sumA);
}

TEST_CASE("box primitives: an instance entered per box is an intersection program per box", "[geometry][bvh][gpu]") {
    // The instances layout counts a BLAS entry per box a ray enters; the aabbs
    // layout of one BLAS runs its intersection program per box entered. Over
    // the same boxes and rays the two counts are equal, ray by ray; and,
    // against boxes formed and slab-tested here from the particles alone,
    // a ray enters at most the boxes it overlaps and at least those it
    // overlaps before its closest hit (traversal may skip boxes behind it).
    GeometrySettings g;
    g.alpha = GENERATE(AlphaMode::opaque, AlphaMode::disc);
    g.cluster_size = 1u << 30;
    const auto [ps, cs] = accretion::test::smallView(400, 3.0, 0.1, Vec3(0.0f, 3.0f, 6.0f), 40, 30);
    GpuSettings gpu;
    gpu.counters = true;
    EmbreeDevice device;
    g.layout = AccelLayout::instances;
    ParticleBvh instances(device, g, gpu);
    g.layout = AccelLayout::aabbs;
    ParticleBvh boxes(device, g, gpu);
    const Particles p = generateDisk(ps, 0);
    const Camera cam = Camera::atFrame(cs, 0);
    instances.build(p, cam);
    boxes.build(p, cam);
    std::uint64_t hits = 0, entries = 0, programs = 0;
    forEachPixelRay(cam, [&](std::uint32_t, std::uint32_t, const Vec3& d) {
        SurfaceHit a, b;
        RayCounters ra, rb;
        const bool ha = instances.intersect(cam.position, d, 1e30f, a, &ra);
        const bool hb = boxes.intersect(cam.position, d, 1e30f, b, &rb);
        REQUIRE(ha == hb);
        if (ha) REQUIRE(a.particle == b.particle);
        REQUIRE(ra.intersections == 0);
        REQUIRE(rb.blasEntries <= 1);  // the one BLAS of boxes, when its bounds are entered
        REQUIRE(ra.blasEntries == rb.intersections);
        REQUIRE(rb.intersections <= overlappedBoxes(p, boxes, cam.position, d, 0.0f, 1e30f, 1e-4f));
        REQUIRE(rb.intersections >= overlappedBoxes(p, boxes, cam.position, d, 0.0f, hb ? b.t * (1.0f - 1e-4f) : 1e30f, -1e-4f));
        hits += ha;
        entries += ra.blasEntries;
        programs += rb.intersections;
    });
    REQUIRE(hits > 50);
    REQUIRE(entries == programs);
    REQUIRE(programs >= hits);
}

TEST_CASE("segment boxes: the particles' boxes a ray crosses, whatever the layout, as a brute-force slab test counts them", "[geometry][bvh][gpu]") {
    // A primary ray counts the boxes it crosses up to its hit, a shadow ray
    // those up to its first blocker and those of its whole segment, the
    // blocker found here by testing every quad; the count is the scene's, not the
    // layout's: one BVH, clusters, boxes and instances give the same. Checked
    // ray by ray against a slab test of every particle formed here, widened
    // and narrowed by a relative margin (boxes grazed at float precision).
    const auto [ps, cs] = accretion::test::smallView(400, 3.0, 0.1, Vec3(0.0f, 3.0f, 6.0f), 40, 30);
    GpuSettings gpu;
    gpu.counters = true;
    EmbreeDevice device;
    const Particles p = generateDisk(ps, 0);
    const Camera cam = Camera::atFrame(cs, 0);
    std::vector<std::unique_ptr<ParticleBvh>> bvhs;
    for (const auto& [layout, size] : {std::pair{AccelLayout::clusters, 1u << 30}, std::pair{AccelLayout::clusters, 25u},
                                       std::pair{AccelLayout::aabbs, 50u}, std::pair{AccelLayout::instances, 1u}}) {
        GeometrySettings g;
        g.layout = layout;
        g.cluster_size = size;
        bvhs.push_back(std::make_unique<ParticleBvh>(device, g, gpu));
        bvhs.back()->build(p, cam);
    }
    auto crossed = [&](const Vec3& o, const Vec3& d, float tnear, float tfar, float slack) {
        return overlappedBoxes(p, *bvhs[0], o, d, tnear, tfar, slack);
    };
    std::vector<BillboardFrame> frames(p.size());
    for (std::uint32_t i = 0; i < p.size(); ++i) frames[i] = bvhs[0]->frame(i);
    std::uint64_t primary = 0, shadow = 0, blockedRays = 0, shadowRays = 0, disagree = 0;
    forEachPixelRay(cam, [&](std::uint32_t x, std::uint32_t y, const Vec3& d) {
        std::uint32_t first = 0, firstVisits = 0;
        for (std::size_t b = 0; b < bvhs.size(); ++b) {
            SurfaceHit h;
            RayCounters rc;
            const bool hit = bvhs[b]->intersect(cam.position, d, 1e30f, h, &rc);
            const float t = hit ? h.t : 1e30f;
            REQUIRE(rc.segmentBoxes <= crossed(cam.position, d, 0.0f, t * (1.0f + 1e-4f), 1e-4f));
            REQUIRE(rc.segmentBoxes >= crossed(cam.position, d, 0.0f, t * (1.0f - 1e-4f), -1e-4f));
            if (b == 0) first = rc.segmentBoxes, firstVisits = rc.nodeVisits;
            REQUIRE(rc.segmentBoxes == first);
            // The traversal model's nodes, too: a ray that enters a box went
            // through the root; no ray visits more than the n - 1 inner nodes.
            REQUIRE(rc.nodeVisits == firstVisits);
            if (rc.segmentBoxes > 0) REQUIRE(rc.nodeVisits >= 1);
            REQUIRE(rc.nodeVisits < p.size());
            REQUIRE(rc.wholeSegmentBoxes == rc.segmentBoxes);  // a primary ray's segment ends at its hit
            if (!hit || b) continue;
            primary += rc.segmentBoxes;
            // A shadow ray from the hit to particle (x * 7 + y) % n: its whole segment.
            const std::uint32_t light = (x * 7u + y) % std::uint32_t(p.size());
            const Vec3 o = cam.position + h.t * d, to = p.position[light] - o;
            const float t0 = 1e-3f, t1 = 1.0f - 1e-3f;
            RayCounters sc;
            const bool blocked = bvhs[b]->occluded(o, to, t0, t1, {}, &sc);
            REQUIRE(sc.wholeSegmentBoxes <= crossed(o, to, t0 * (1.0f - 1e-4f), t1 * (1.0f + 1e-4f), 1e-4f));
            REQUIRE(sc.wholeSegmentBoxes >= crossed(o, to, t0 * (1.0f + 1e-4f), t1 * (1.0f - 1e-4f), -1e-4f));
            // Up to the first blocker, found here by testing every particle's quad.
            std::uint32_t blocker;
            const float first = bruteForce(p, frames, GeometrySettings{}, o, to, t1, blocker, t0);
            disagree += blocked != (first < t1);  // a quad grazed at float precision
            REQUIRE(sc.segmentBoxes <= crossed(o, to, t0 * (1.0f - 1e-4f), first * (1.0f + 1e-4f), 1e-4f));
            REQUIRE(sc.segmentBoxes >= crossed(o, to, t0 * (1.0f + 1e-4f), first * (1.0f - 1e-4f), -1e-4f));
            REQUIRE(sc.segmentBoxes <= sc.wholeSegmentBoxes);
            if (sc.segmentBoxes > 0) REQUIRE(sc.nodeVisits >= 1);
            REQUIRE(sc.nodeVisits < p.size());
            if (!(first < t1)) REQUIRE(sc.segmentBoxes == sc.wholeSegmentBoxes);
            blockedRays += blocked;
            ++shadowRays;
            shadow += sc.wholeSegmentBoxes;
        }
    });
    REQUIRE(primary > 20);
    REQUIRE(shadow > primary);  // shadow segments cross the disk; primary rays stop at their first particle
    REQUIRE(blockedRays > 0);
    REQUIRE(blockedRays < shadowRays);
    REQUIRE(disagree * 50 <= shadowRays);  // the traced scene and the quads tested here agree on blockers
}

TEST_CASE("the CPU traces one BVH unless counting, asked for the GPU's layout, or partial", "[geometry][bvh]") {
    GeometrySettings g;
    g.layout = AccelLayout::aabbs;
    g.cluster_size = 100;
    const GeometrySettings fastest = cpuGeometry(g, false);
    REQUIRE(fastest.layout == AccelLayout::clusters);
    REQUIRE(fastest.cluster_size == std::numeric_limits<std::uint32_t>::max());
    REQUIRE(describeLayout(fastest).find("one BVH of every particle") == 0);
    REQUIRE(cpuGeometry(g, true).layout == AccelLayout::aabbs);  // counting: the GPU's
    g.cpu_layout = CpuLayout::gpu;
    REQUIRE(cpuGeometry(g, false).cluster_size == 100);
    g.cpu_layout = CpuLayout::fastest;
    g.build = BuildPolicy::partial;  // stale clusters are part of the image
    REQUIRE(cpuGeometry(g, false).layout == AccelLayout::aabbs);
}
