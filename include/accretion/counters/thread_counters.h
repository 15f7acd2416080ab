#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "accretion/core/pass.h"

namespace accretion {

// The GPU counters as tables (docs/MODEL.md section 6): each row is a
// counter's member, its key in the reports' JSON, and what it counts. The
// counter structs below, their sums (over a thread's rays, over a pass's
// threads: PassReport in gpu/gpu_report.h) and the JSON keys are all
// derived from these rows; the cost model's features (gpu/cost_model.h's
// kCostFeatureTable) read the sums by member.

/// What a ray query records, summed over a thread's rays.
#define ACC_RAY_COUNTERS(X)                                                                                              \
    X(blasEntries, "blas_entries", "TLAS leaves entered (BLAS traversals started)")                                      \
    X(anyHits, "any_hit", "any-hit invocations (alpha-tested candidates)")                                               \
    X(blasLevels, "blas_levels", "per BLAS entered, its depth: ceil(log2(primitives)) (traversal inside it)")           \
    X(ommLookups, "omm_lookups", "candidate hits on micromapped triangles (the micromap looked up)")                     \
    X(intersections, "intersections", "intersection-program invocations: boxes (aabbs layout) or spheres whose bounds "  \
                                      "the ray entered")                                                                 \
    X(misses, "misses", "1 when the query found nothing (a shadow ray unblocked): it traversed its whole segment")       \
    X(segmentBoxes, "segment_boxes", "particles' boxes the ray crosses up to its hit or first blocker (where a "         \
                                     "terminate-on-first-hit traversal may stop)")                                       \
    X(wholeSegmentBoxes, "whole_segment_boxes", "the same over its whole segment (where it may have to look)")      \
    X(nodeVisits, "node_visits", "inner BVH nodes its traversal visits (geometry/traversal_model.h: a binary BVH "      \
                                 "over the particles' boxes, nearer child first, stopping at a shadow ray's first "    \
                                 "blocker)")

/// What a thread records of its own work, summed over a pass's threads.
#define ACC_THREAD_COUNTERS(X)                                                                                           \
    X(trips, "trips", "loop trips (candidates, neighbours, samples)")                                                   \
    X(rays, "rays", "rays traced")                                                                                       \
    X(proceeds, "proceeds", "RayQuery Proceed() iterations: candidates + 1 per ray")                                    \
    X(bytesRead, "bytes_read", "G-buffer, reservoirs, particle records read")                                           \
    X(gathers, "gathers", "reads at an index drawn or looked up, each a memory round trip the next step waits for: a "  \
                          "light's record, an alias entry, a tree node, a tile's entry; what a read costs beyond its "   \
                          "bytes (power candidates: 1.2x uniform's bytes, 2x their reads, 1.6-2x their time on the H100)") \
    X(bytesWritten, "bytes_written", "G-buffer, reservoirs, radiance written")

#define ACC_COUNTER_FIELD(member, key, doc) std::uint32_t member = 0;

/// What one ray query did, as a GPU would count it (ACC_RAY_COUNTERS). Its
/// boxes crossed say how much of the scene a ray crosses (a long ray
/// through the dense inner disk enters many boxes whose particles it
/// misses); BLAS depths say how deep it descends.
struct RayCounters {
    std::uint32_t candidates = 0;   ///< non-opaque candidates seen (RayQuery Proceed() returning true)
    ACC_RAY_COUNTERS(ACC_COUNTER_FIELD)
};

/// The work of one pixel's thread in one pass (docs/MODEL.md section 6):
/// ACC_THREAD_COUNTERS and the sums of ACC_RAY_COUNTERS over its rays. The
/// branch key of a thread is (hit, type): a miss is key 0, a hit on a
/// particle of type t is key 1 + t. cluster and hint feed SER sort keys.
struct ThreadCounters {
    std::uint8_t active = 0;        ///< the thread exists (pixel inside the dispatch)
    std::uint8_t hit = 0;           ///< primary hit (else the miss path)
    std::uint8_t type = 0;          ///< particle type of the hit
    std::uint32_t cluster = 0;      ///< cluster (BLAS) of the hit
    std::uint32_t hint = 0;         ///< coherence hint (e.g. the sampled light's cluster)
    ACC_THREAD_COUNTERS(ACC_COUNTER_FIELD)
    ACC_RAY_COUNTERS(ACC_COUNTER_FIELD)

    std::uint32_t branchKey() const { return hit ? 1u + type : 0u; }
    /// n rays whose counters sum to r.
    void addRays(const RayCounters& r, std::uint32_t n) {
        rays += n;
        proceeds += r.candidates + n;
#define ACC_ADD_RAY(member, key, doc) member += r.member;
        ACC_RAY_COUNTERS(ACC_ADD_RAY)
#undef ACC_ADD_RAY
    }
    void addRay(const RayCounters& r) { addRays(r, 1); }
};

#undef ACC_COUNTER_FIELD

/// buildClusters' acceleration-structure work as the cost model prices it.
/// Every build or refit, of a BLAS or of the TLAS, is a launch plus a cost
/// per element (primitive or instance) that falls as the build grows (a
/// small build leaves the GPU idle, a big one fills it): its elements are
/// counted whole and clamped at two knots (Sigma n, Sigma min(n, 1024),
/// Sigma min(n, 32768)), once over everything built or refitted and once
/// more over what was built (a build does more per element than a refit,
/// which only recomputes boxes). The TLAS counts as a build of its
/// instances like any other: an OptiX TLAS is a BVH over instance boxes.
struct BuildCounters {
    std::uint64_t builds = 0, refits = 0;   ///< launches, BLAS and TLAS
    std::uint64_t blasBuilds = 0, blasRefits = 0;  ///< of them, the BLAS's
    std::uint64_t elements = 0, elementsSmall = 0, elementsMid = 0;      ///< built or refitted
    std::uint64_t primitives = 0, primitivesSmall = 0, primitivesMid = 0;  ///< built
    std::uint64_t customBuilds = 0;  ///< BLAS builds of procedural boxes or spheres (dearer than triangles')
    /// BLAS refits of built-in spheres: 1.5x a refit of triangles or boxes on the H100 (1000 clusters of 1000: 57 ms against 38 and 36)
    std::uint64_t sphereRefits = 0;
    std::uint64_t tlasInstances = 0;
    /// Instances of TLAS builds (not refits), clamped per build at 32768: on
    /// the H100 a TLAS over 10K instances builds in 0.26 ms where a BLAS of
    /// 20K triangles takes 0.15 (an instance's box is its child's, transformed).
    std::uint64_t tlasInstancesMid = 0;
    static constexpr std::uint64_t kSmallKnot = 1024, kMidKnot = 32768;
    static std::uint64_t small(std::uint64_t n) { return n < kSmallKnot ? n : kSmallKnot; }
    static std::uint64_t mid(std::uint64_t n) { return n < kMidKnot ? n : kMidKnot; }
    /// One BLAS of n primitives built, or refitted.
    void addBlas(std::uint64_t n, bool custom, bool refit = false, bool spheres = false) {
        add(n, refit);
        (refit ? blasRefits : blasBuilds) += 1;
        customBuilds += custom && !refit;
        sphereRefits += spheres && refit;
    }
    /// The TLAS over n instances built, or refitted.
    void addTlas(std::uint64_t n, bool refit) {
        add(n, refit);
        tlasInstances = n;
        if (!refit) tlasInstancesMid += mid(n);
    }

private:
    void add(std::uint64_t n, bool refit) {
        (refit ? refits : builds) += 1;
        elements += n;
        elementsSmall += small(n);
        elementsMid += mid(n);
        if (refit) return;
        primitives += n;
        primitivesSmall += small(n);
        primitivesMid += mid(n);
    }
};

/// One pass's dispatch: a width x height grid of threads (pixels; for
/// buildClusters one thread per cluster, height 1).
struct PassCounters {
    Pass pass = Pass::traceGBuffer;
    std::uint32_t run = 1;  ///< 1 for a pass's first run in the frame, 2 for its second (spatial iterations)...
    std::uint32_t width = 0, height = 0;
    std::vector<ThreadCounters> threads;
    std::uint64_t dispatches = 1;  ///< kernel dispatches (a cost model feature); builds are in `build`
    BuildCounters build;           ///< buildClusters only
    /// Distinct bytes of the grids the pass's threads read at other threads'
    /// texels, each once (upsampleLighting's lighting grid: four pixels share
    /// a texel at half resolution, fewer at 0.75): its traffic from memory,
    /// where the per-thread bytes count what the threads ask of the caches.
    std::uint64_t footprintBytes = 0;
    /// Steps of the pass's kernels over other items than its grid, summed
    /// over those kernels: a step per item of a kernel that does one thing
    /// an item (gatherParticleTexels' select over every particle, its keys,
    /// sort and texels), and per loop trip of one that loops
    /// (updateVoxelCache's marking: a thread per particle storing each cell
    /// of its reach, a step per 32-byte sector a warp's store touches).
    /// Their time grows with the particles where the grid's does not.
    std::uint64_t itemSteps = 0;

    PassCounters() = default;
    PassCounters(Pass p, std::uint32_t w, std::uint32_t h) : pass(p), width(w), height(h), threads(std::size_t(w) * h) {}
    PassRun id() const { return {pass, run}; }
};

/// The acceleration structures of a frame as the GPU memory model reads
/// them: triangles (or spheres) per BLAS, Embree's bytes, the micromap.
/// The opacity micromap of a frame, when disc alpha has one.
struct OmmCounters {
    bool enabled = false;
    std::uint32_t level = 0;
    bool fourState = false;
    std::uint64_t opaque = 0, transparent = 0, unknown = 0;  ///< micro-triangles of the two uv triangles
    std::uint64_t sharedBytes = 0, perTriangleBytes = 0;
};

struct AccelCounters {
    std::vector<std::uint32_t> blasPrimitives;  ///< per GPU BLAS: triangles (2 per billboard), spheres or boxes
    std::uint64_t tlasInstances = 0;            ///< TLAS instances: one per BLAS, or per particle (instances layout)
    std::uint64_t particles = 0;
    std::int64_t embreeBytes = 0;
    OmmCounters omm;
};

/// Counters of every pass of a frame, in execution order. Each run of a
/// pass is its own record (see PassCounters::run).
struct FrameCounters {
    std::vector<PassCounters> passes;
    AccelCounters accel;  ///< the frame's BVH, for the memory model

    /// The record of a pass about to run.
    PassCounters& add(Pass pass, std::uint32_t w, std::uint32_t h) {
        std::uint32_t run = 1;
        for (const PassCounters& p : passes) run += p.pass == pass;
        passes.emplace_back(pass, w, h).run = run;
        return passes.back();
    }
    bool empty() const { return passes.empty(); }
};

/// The compile-time switch of the passes: Recorder<false> compiles to nothing.
template <bool On> struct Recorder;

template <> struct Recorder<false> {
    explicit Recorder(ThreadCounters*) {}
    static constexpr bool on = false;
    void shade(bool, std::uint32_t, std::uint32_t) {}
    void trip(std::uint32_t = 1) {}
    void ray(const RayCounters&) {}
    void read(std::uint32_t) {}
    void gather(std::uint32_t) {}
    void write(std::uint32_t) {}
    void hint(std::uint32_t) {}
    void rays(const RayCounters&, std::uint32_t) {}
    RayCounters* rayCounters(RayCounters&) { return nullptr; }
};

template <> struct Recorder<true> {
    explicit Recorder(ThreadCounters* t) : t_(t) { t_->active = 1; }
    static constexpr bool on = true;
    void shade(bool hit, std::uint32_t type, std::uint32_t cluster) {
        t_->hit = hit;
        t_->type = static_cast<std::uint8_t>(type);
        t_->cluster = cluster;
    }
    void trip(std::uint32_t n = 1) { t_->trips += n; }
    void ray(const RayCounters& r) { t_->addRay(r); }
    void rays(const RayCounters& r, std::uint32_t n) { t_->addRays(r, n); }
    void read(std::uint32_t bytes) { t_->bytesRead += bytes; }
    void gather(std::uint32_t n) { t_->gathers += n; }
    void write(std::uint32_t bytes) { t_->bytesWritten += bytes; }
    void hint(std::uint32_t h) { t_->hint = h; }
    RayCounters* rayCounters(RayCounters& r) { r = RayCounters{}; return &r; }

private:
    ThreadCounters* t_;
};

}  // namespace accretion
