#pragma once
#include <bit>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "accretion/geometry/billboard.h"
#include "accretion/geometry/clustering.h"
#include "accretion/geometry/exclusion.h"
#include "accretion/geometry/embree_device.h"
#include "accretion/geometry/opacity_micromap.h"
#include "accretion/geometry/traversal_model.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/settings.h"

namespace accretion {

struct Camera;

/// What one build of the acceleration structure did and holds.
struct BvhStats {
    std::size_t clusters = 0;       ///< BLAS count (= TLAS instances)
    std::size_t primitives = 0;     ///< the GPU's primitives: triangles (billboards) or spheres
    std::size_t triangles = 0;      ///< 2 per billboard (Embree holds one quad), 0 for spheres
    bool built = true;              ///< false: a static scene's BVH reused from an earlier frame
    bool reclustered = false;       ///< clusters recomputed this frame
    bool refitted = false;          ///< BLAS refitted instead of rebuilt
    bool partial = false;           ///< partial rebuild: only rebuiltClusters were updated
    std::size_t rebuiltClusters = 0;///< BLAS built or refitted this frame
    double clusterSeconds = 0.0;    ///< spatial clustering time
    double blasSeconds = 0.0;       ///< all bottom-level builds (parallel)
    double tlasSeconds = 0.0;       ///< top-level build
    std::int64_t embreeBytes = 0;   ///< Embree's memory after the build (memory monitor)
    std::string layout;             ///< what was built, in words (describeLayout)
};

/// A primary-ray hit, decoded to the particle.
struct SurfaceHit {
    std::uint32_t particle;  ///< global particle index
    std::uint32_t cluster;   ///< cluster (TLAS instance) id
    float t;                 ///< ray distance
    Vec2 uv;                 ///< quad uv (billboards)
};

/// The any-hit of disc-alpha billboards: an opacity micromap (if any) decides
/// opaque and transparent micro-triangles without invoking it.
struct AlphaTest {
    const OpacityMicromap* omm = nullptr;
};

/// One particle of a BLAS of box primitives (Embree user geometry): its centre and radius.
struct BoxPrimitive {
    Vec3 p;
    float r;
};

/// What a BLAS of box primitives reads (the user data of its geometry).
struct BoxBlas {
    const BoxPrimitive* prims = nullptr;     ///< the cluster's slots
    const std::uint32_t* members = nullptr;  ///< the cluster's particles
    const BillboardFrame* frames = nullptr;  ///< every particle's frame
    const AlphaTest* alpha = nullptr;
    bool disc = false;       ///< disc alpha
    bool sphere = false;     ///< spheres (else billboards)
    bool instances = false;  ///< a box is a TLAS instance (instances layout), else an intersection program (aabbs, spheres)
};

/// What the counting probe reads (every particle's box, whatever the
/// layout): per particle its box, centre and radius, and frame.
struct ProbeData {
    const RTCBounds* boxes = nullptr;
    const BoxPrimitive* prims = nullptr;
    const BillboardFrame* frames = nullptr;
    bool sphere = false;  ///< spheres (else billboards)
    bool disc = false;    ///< billboards with the disc alpha test
};

/// The particles' boxes a segment crosses: all of them, and those it enters
/// before its first blocker (all when nothing blocks it).
struct BoxesCrossed {
    std::uint32_t untilBlocker = 0, whole = 0;
};

/// The structure the CPU traces for `g`: the GPU's layout when counting (its
/// counters are the GPU's), when asked (cpu_layout = gpu), or under the
/// partial policy (its stale clusters are part of the image); else the
/// fastest on the CPU, one BVH of every particle (measured on disk_100k:
/// 1.6x the shadow rays per second of clusters of 100), whose image is the same.
GeometrySettings cpuGeometry(const GeometrySettings& g, bool counting);
/// The layout a GeometrySettings traces, in words ("one BVH of every particle", "clusters of 100", ...).
std::string describeLayout(const GeometrySettings& g);

/// The GPU's acceleration structure on Embree (docs/MODEL.md section 2): one BLAS
/// per particle cluster, instanced in a TLAS; billboards as quads (the GPU's two triangles)
/// (optionally with the disc alpha test as a filter function) or spheres. The
/// aabbs layout's BLAS hold box primitives (user geometry) that run the
/// billboard's intersection program; the instances layout is one BLAS of
/// boxes, each box one TLAS instance of the unit billboard; counted spheres
/// are boxes too (the GPU's sphere test runs per box entered).
class ParticleBvh {
public:
    /// counting: also build a TLAS of user-geometry instances that count the
    /// BLAS entries of each ray (used only by queries given RayCounters).
    ParticleBvh(const EmbreeDevice& device, const GeometrySettings& settings, const GpuSettings& gpu = GpuSettings{});
    ~ParticleBvh();
    ParticleBvh(const ParticleBvh&) = delete;
    ParticleBvh& operator=(const ParticleBvh&) = delete;

    /// Build (rebuild / refit / fast_trace, per the settings) for a frame.
    void build(const Particles& particles, const Camera& camera);

    /// Closest hit along o + t d, t in [0, tfar). d need not be unit. With
    /// counters (counting mode only), the BLAS entries and any-hits are added.
    bool intersect(const Vec3& o, const Vec3& d, float tfar, SurfaceHit& hit, RayCounters* counters = nullptr) const;
    /// Closest hits of up to 8 rays from one origin (a packet: coherent
    /// primary rays trace ~1.6x faster); found[k] says whether ray k hit.
    /// Lanes k >= n are inactive. Not for counting.
    void intersect8(const Vec3& o, const Vec3* d, int n, SurfaceHit* hit, bool* found) const;
    /// Any hit along o + t d, t in [tnear, tfar], of a particle other than
    /// the excluded ones (after its alpha test): the search stops at the
    /// first. With counters (counting mode only), entries and any-hits are added.
    bool occluded(const Vec3& o, const Vec3& d, float tnear, float tfar, Exclusion exclude = {},
                  RayCounters* counters = nullptr) const;

    /// The TLAS (for bare Embree loops over the same BVH: benchmarks).
    RTCScene scene() const { return tlas_; }
    /// True when queries can count (the counting TLAS is built).
    bool counting() const { return counting_; }
    /// The opacity micromap in use (null without one).
    const OpacityMicromap* micromap() const { return omm_.get(); }
    /// What the GPU memory model reads of this BVH: primitives per BLAS, Embree bytes, the micromap.
    AccelCounters accelCounters() const;
    /// Hint that occlusion queries excluding particle i will follow (its
    /// identity key is a random read).
    void prefetchExclusion(std::uint32_t i) const { __builtin_prefetch(&where_[i]); }
    /// Cluster of particle i.
    std::uint32_t clusterOf(std::uint32_t i) const { return static_cast<std::uint32_t>(where_[i] >> 32); }
    /// BLAS of cluster c (for the counting instances).
    RTCScene blas(std::size_t c) const { return blas_[c]; }
    /// World bounds of cluster c's BLAS in the current build.
    const RTCBounds& blasBounds(std::size_t c) const { return blasBounds_[c]; }
    /// The depth of cluster c's BLAS as the GPU builds it: ceil(log2) of its
    /// primitives (two triangles per billboard), the levels a ray entering it may descend.
    std::uint32_t blasLevels(std::size_t c) const {
        if (settings_.layout == AccelLayout::instances) return 0;  // the boxes count their instances
        const auto n = static_cast<std::uint32_t>(clusters_.members(c).size()) *
                       (settings_.primitive == Primitive::billboard && settings_.layout == AccelLayout::clusters ? 2u : 1u);
        return n > 1 ? static_cast<std::uint32_t>(std::bit_width(n - 1)) : 0u;
    }

    /// The billboard frame of a particle in the current build.
    const BillboardFrame& frame(std::uint32_t particle) const { return frames_[particle]; }
    const Clusters& clusters() const { return clusters_; }
    const BvhStats& stats() const { return stats_; }
    const GeometrySettings& settings() const { return settings_; }

private:
    void releaseBlas();
    void buildBlas(std::size_t c, const Particles& particles, bool create);
    void createBlas(std::size_t c);
    void writePrimitives(std::size_t c, const Particles& particles, bool create);
    void buildTlas();
    void buildCountingTlas();
    /// refit: the GPU refits its BVH, and the traversal model keeps its topology.
    void buildProbe(const Particles& particles, bool refit);
    /// The particles' boxes that o + t d, t in [tnear, tfar], passes through
    /// (the probe: every particle's box in one BVH, whatever the layout),
    /// and for an occlusion query those entered before its first blocker
    /// (other than the excluded particles), where the GPU's traversal stops:
    /// one blocker search, one count.
    BoxesCrossed boxesAlong(const Vec3& o, const Vec3& d, float tnear, float tfar, const Exclusion* occlusion = nullptr) const;
    /// The BLAS hold box primitives (user geometry) rather than Embree's quads or spheres.
    bool boxPrimitives() const {
        return settings_.layout != AccelLayout::clusters || (counting_ && settings_.primitive == Primitive::sphere);
    }

    const EmbreeDevice& device_;
    GeometrySettings settings_;
    Clusters clusters_;
    std::vector<BillboardFrame> frames_;
    std::vector<RTCScene> blas_;
    std::vector<RTCGeometry> geometry_;  // one per BLAS, owned by its scene
    std::vector<BoxPrimitive> boxes_;    // box primitives: per slot of clusters_.particle
    std::vector<BoxBlas> boxBlas_;       // box primitives: per BLAS, its geometry's user data
    RTCScene tlas_ = nullptr;
    bool counting_ = false;
    RTCScene countingTlas_ = nullptr;      ///< user-geometry instances that count entries
    std::vector<RTCBounds> blasBounds_;
    RTCScene probe_ = nullptr;           ///< counting: one BVH of every particle's box (RayCounters::segmentBoxes)
    std::vector<RTCBounds> probeBoxes_;  ///< per particle, its primitive's world box
    std::vector<BoxPrimitive> probePrims_;  ///< per particle, its centre and radius
    ProbeData probeData_{};                 ///< the probe geometry's user data
    TraversalModel traversal_;              ///< counting: the GPU traversal's nodes (RayCounters::nodeVisits)
    /// particle -> (cluster << 32 | its primitive in the cluster's BLAS): the
    /// key an occlusion query's filter compares with Embree's (instID, primID)
    std::vector<std::uint64_t> where_;
    std::unique_ptr<OpacityMicromap> omm_;
    AlphaTest alpha_;
    std::size_t partialCursor_ = 0;  ///< partial: first cluster of the next window
    BvhStats stats_;
};

}  // namespace accretion
