#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "accretion/core/pass.h"
#include "accretion/gpu/gpu_report.h"

namespace accretion {

/// The reads that miss a cache of `cacheBytes`: a traced pass's rays (else
/// its bytes) times the levels of a tree over the working set that the cache
/// cannot hold, log2(working set / cache), 0 when it fits. A BVH keeps its
/// top levels cached and misses below them; random reads of a table grow
/// their misses as it outgrows the cache (the H100 sweep of bench/gpu: 1M
/// particles cost the G-buffer 1.7x the rays of 100K, with fewer BLAS levels).
double coldWork(double rays, double bytes, double workingSetBytes, double cacheBytes);

/// The counters a pass's predicted time is linear in (docs/MODEL.md section
/// 6). The first six are the model's first form; the others came with
/// measurements on a GPU (bench/gpu): the traversal inside the BLAS entered
/// (their depths), micromap lookups (software on a GPU without RT cores),
/// kernel dispatches, cold_work (coldWork: random reads of a working set
/// larger than a cache), the TLAS levels a ray descends (rays x log2 of the
/// instances), the intersection-program invocations and the rays that found
/// nothing (a ray that misses, or a shadow ray unblocked, traverses its
/// whole segment; a blocked one stops at its first blocker) and the
/// particles' boxes the rays crossed, whatever the layout (segment_boxes: a
/// shadow ray's up to its first blocker; whole_segment_boxes: over its
/// whole segment; what a ray's length through the scene costs its
/// traversal), and the
/// gathers (reads at a drawn or looked-up index, each a round trip: a
/// power candidate's alias entry and light). The builds
/// (BuildCounters): launches of builds and refits, BLAS or TLAS, each a
/// constant; the elements built or refitted, whole and clamped per build at
/// 1024 and 32768 (a build's cost per element falls as it fills the GPU);
/// the same over the builds alone (what a build does beyond a refit); the
/// builds of boxes or spheres, the refits of built-in spheres, and the
/// instances of TLAS builds clamped at 32768 (tlas_instances_32k). Two
/// terms of a traversal's length: warp_segment_boxes, per warp its longest
/// lane's segment boxes summed over the warps (a warp waits for its longest
/// ray), and dispatch_path, the dispatches times the mean segment boxes of
/// a ray (a launch lasts at least one ray's traversal, whatever its size:
/// what a launch of few rays costs beyond their throughput). Two terms of
/// a warp's latency: warp_gathers, per warp its longest lane's gathers (a
/// chain of dependent reads), and hit_warps, the warps with a lane on a
/// particle (on the H100 the spatial pass at 720p costs 72, 86 and 78 ns
/// per such warp at 10K, 100K and 1M particles, whose warps hold 6, 20 and
/// 31 hit lanes). footprint_bytes: the distinct bytes of the grids read at
/// other threads' texels (the lighting grid of upsampling: 1.5x the time at
/// scale 0.75 as at 0.5, for the same bytes asked). item_steps: the steps
/// of a pass's kernels over other items than its grid. node_visits: the
/// inner BVH nodes the rays' traversals visit (geometry/traversal_model.h:
/// a ray through the gaps of a dense volume visits nodes whose particles it
/// never crosses), and warp_node_visits, per warp its longest lane's (a
/// GPU that traverses in software, as the H100, runs a warp's traversal
/// loop until its last lane is done). Counter CSVs without a column read it
/// as 0.
enum class CostFeature : std::uint8_t {
    threads, warp_steps, rays, blas_entries, any_hits, bytes, blas_levels, omm_lookups, dispatches, build_launches,
    refit_launches, cold_work, accel_elements, accel_elements_1k, accel_elements_32k, build_primitives, build_primitives_1k,
    build_primitives_32k, custom_builds, intersections, tlas_levels, misses, segment_boxes, gathers, sphere_refits,
    warp_segment_boxes, dispatch_path, whole_segment_boxes, warp_gathers, hit_warps, footprint_bytes, tlas_instances_32k,
    item_steps, node_visits, warp_node_visits,
};
inline constexpr std::size_t kCostFeatureCount = std::size_t(CostFeature::warp_node_visits) + 1;

/// One row of the cost model's feature table: everything about a feature
/// that the model, the counter CSVs, the coefficient files and calibrate read.
struct CostFeatureInfo {
    CostFeature feature;
    std::string_view name;  ///< its column in counters.csv and key in coefficient files
    /// Of the model's first form (shared): required in every counter CSV and
    /// coefficient file (the later ones read as 0 where absent).
    bool firstForm;
    /// Prices acceleration-structure builds: buildClusters is fitted on
    /// these (and dispatches) alone, every other pass on the rest. A pass's
    /// counters of the other kind are 0 or, like the build pass's threads
    /// (one per cluster: collinear with its launches), say nothing of its
    /// time, and a fit that gives them weight extrapolates badly.
    bool build;
    /// A launch constant (a dispatch, a build or refit launch): always kept
    /// by the selected form, whose forward selection adds work counters.
    bool launch;
    /// Its value for a pass (cold_work for a cache of `cacheBytes`).
    double (*value)(const PassReport& pass, double cacheBytes);
};

namespace detail {
using P = const PassReport&;
inline double bytesOf(P p) { return double(p.bytesRead + p.bytesWritten); }
}  // namespace detail

inline constexpr std::array<CostFeatureInfo, kCostFeatureCount> kCostFeatureTable = {{
    {CostFeature::threads, "threads", true, false, false, [](detail::P p, double) { return double(p.threads); }},
    {CostFeature::warp_steps, "warp_steps", true, false, false, [](detail::P p, double) { return double(p.warpSteps()); }},
    {CostFeature::rays, "rays", true, false, false, [](detail::P p, double) { return double(p.rays); }},
    {CostFeature::blas_entries, "blas_entries", true, false, false, [](detail::P p, double) { return double(p.blasEntries); }},
    {CostFeature::any_hits, "any_hits", true, false, false, [](detail::P p, double) { return double(p.anyHits); }},
    {CostFeature::bytes, "bytes", true, false, false, [](detail::P p, double) { return detail::bytesOf(p); }},
    {CostFeature::blas_levels, "blas_levels", false, false, false, [](detail::P p, double) { return double(p.blasLevels); }},
    {CostFeature::omm_lookups, "omm_lookups", false, false, false, [](detail::P p, double) { return double(p.ommLookups); }},
    {CostFeature::dispatches, "dispatches", false, false, true, [](detail::P p, double) { return double(p.dispatches); }},
    {CostFeature::build_launches, "build_launches", false, true, true, [](detail::P p, double) { return double(p.build.builds); }},
    {CostFeature::refit_launches, "refit_launches", false, true, true, [](detail::P p, double) { return double(p.build.refits); }},
    {CostFeature::cold_work, "cold_work", false, false, false,
     [](detail::P p, double cache) { return coldWork(double(p.rays), detail::bytesOf(p), p.workingSetBytes, cache); }},
    {CostFeature::accel_elements, "accel_elements", false, true, false, [](detail::P p, double) { return double(p.build.elements); }},
    {CostFeature::accel_elements_1k, "accel_elements_1k", false, true, false, [](detail::P p, double) { return double(p.build.elementsSmall); }},
    {CostFeature::accel_elements_32k, "accel_elements_32k", false, true, false, [](detail::P p, double) { return double(p.build.elementsMid); }},
    {CostFeature::build_primitives, "build_primitives", false, true, false, [](detail::P p, double) { return double(p.build.primitives); }},
    {CostFeature::build_primitives_1k, "build_primitives_1k", false, true, false,
     [](detail::P p, double) { return double(p.build.primitivesSmall); }},
    {CostFeature::build_primitives_32k, "build_primitives_32k", false, true, false,
     [](detail::P p, double) { return double(p.build.primitivesMid); }},
    {CostFeature::custom_builds, "custom_builds", false, true, false, [](detail::P p, double) { return double(p.build.customBuilds); }},
    {CostFeature::intersections, "intersections", false, false, false, [](detail::P p, double) { return double(p.intersections); }},
    {CostFeature::tlas_levels, "tlas_levels", false, false, false, [](detail::P p, double) { return double(p.tlasLevels); }},
    {CostFeature::misses, "misses", false, false, false, [](detail::P p, double) { return double(p.misses); }},
    {CostFeature::segment_boxes, "segment_boxes", false, false, false, [](detail::P p, double) { return double(p.segmentBoxes); }},
    {CostFeature::gathers, "gathers", false, false, false, [](detail::P p, double) { return double(p.gathers); }},
    {CostFeature::sphere_refits, "sphere_refits", false, true, false, [](detail::P p, double) { return double(p.build.sphereRefits); }},
    {CostFeature::warp_segment_boxes, "warp_segment_boxes", false, false, false,
     [](detail::P p, double) { return double(p.ser.traversalBefore.steps); }},
    {CostFeature::dispatch_path, "dispatch_path", false, false, false,
     [](detail::P p, double) { return p.rays ? double(p.dispatches) * double(p.segmentBoxes) / double(p.rays) : 0.0; }},
    {CostFeature::whole_segment_boxes, "whole_segment_boxes", false, false, false,
     [](detail::P p, double) { return double(p.wholeSegmentBoxes); }},
    {CostFeature::warp_gathers, "warp_gathers", false, false, false, [](detail::P p, double) { return double(p.ser.gathersBefore.steps); }},
    {CostFeature::hit_warps, "hit_warps", false, false, false, [](detail::P p, double) { return double(p.ser.hitsBefore.warps); }},
    {CostFeature::footprint_bytes, "footprint_bytes", false, false, false, [](detail::P p, double) { return p.footprintBytes; }},
    {CostFeature::tlas_instances_32k, "tlas_instances_32k", false, true, false,
     [](detail::P p, double) { return double(p.build.tlasInstancesMid); }},
    {CostFeature::item_steps, "item_steps", false, false, false, [](detail::P p, double) { return double(p.itemSteps); }},
    {CostFeature::node_visits, "node_visits", false, false, false, [](detail::P p, double) { return double(p.nodeVisits); }},
    {CostFeature::warp_node_visits, "warp_node_visits", false, false, false,
     [](detail::P p, double) { return double(p.ser.nodesBefore.steps); }},
}};

namespace detail {
constexpr bool costTableInOrder() {
    for (std::size_t k = 0; k < kCostFeatureTable.size(); ++k)
        if (std::size_t(kCostFeatureTable[k].feature) != k) return false;
    return true;
}
constexpr std::size_t firstFormCount() {
    std::size_t n = 0;
    while (n < kCostFeatureTable.size() && kCostFeatureTable[n].firstForm) ++n;
    for (std::size_t k = n; k < kCostFeatureTable.size(); ++k)
        if (kCostFeatureTable[k].firstForm) return 0;  // the first form's features come first
    return n;
}
constexpr std::array<std::string_view, kCostFeatureCount> costFeatureNames() {
    std::array<std::string_view, kCostFeatureCount> names{};
    for (std::size_t k = 0; k < names.size(); ++k) names[k] = kCostFeatureTable[k].name;
    return names;
}
}  // namespace detail
static_assert(detail::costTableInOrder(), "kCostFeatureTable row k describes CostFeature k");

/// The features' names, in table order (the columns of counters.csv).
inline constexpr std::array<std::string_view, kCostFeatureCount> kCostFeatures = detail::costFeatureNames();
/// The model's first form: the first kBaseCostFeatures features of the table.
inline constexpr std::size_t kBaseCostFeatures = detail::firstFormCount();
static_assert(kBaseCostFeatures > 0, "the first form's features come first in the table");
constexpr bool isBuildFeature(std::size_t k) { return kCostFeatureTable[k].build; }

/// One value per feature, indexed by position or by CostFeature.
struct CostFeatures : std::array<double, kCostFeatureCount> {
    using std::array<double, kCostFeatureCount>::operator[];
    double& operator[](CostFeature f) { return (*this)[std::size_t(f)]; }
    double operator[](CostFeature f) const { return (*this)[std::size_t(f)]; }
};

/// The committed calibration (compiled in from this file of the source tree,
/// which CMakeLists.txt names).
inline constexpr const char* kDefaultCoefficientsFile = ACCRETION_DEFAULT_COEFFICIENTS_FILE;
/// Its text (generated/default_coefficients.cpp).
const char* defaultCoefficientsJson();

/// The cache the working-set term assumes before calibration (calibrate
/// chooses its own by cross-validation).
inline constexpr double kDefaultCacheBytes = 4.0 * 1024 * 1024;

/// The model's forms. shared: one coefficient per base counter for every
/// pass, fitted by least squares on ms (the first form). per_pass: each
/// pass its own coefficients over every counter, launches included, fitted
/// on relative error (passes differ in what bounds them: builds by their
/// launches, resampling by memory, shadow rays by traversal). selected:
/// per_pass over the counters that predict configurations left out of the
/// fit (forward selection by leave-one-configuration-out error within the
/// fitted rows): 11 counters fitted on 15 configurations follow their
/// noise, and extrapolate badly.
enum class CostModelForm { shared, per_pass, selected };
inline const char* costModelFormName(CostModelForm f) {
    return f == CostModelForm::shared ? "shared" : f == CostModelForm::per_pass ? "per_pass" : "selected";
}

/// Every feature's value for a pass (the table's value column).
CostFeatures costFeatures(const PassReport& pass, double cacheBytes);

/// Nanoseconds per unit of each feature: predicted time = sum coefficient x counter.
struct CostCoefficients {
    CostFeatures ns{};
    std::map<Pass, CostFeatures> perPass;  ///< per_pass form: by pass (spatialResampling[2] uses spatialResampling's)
    double cacheBytes = kDefaultCacheBytes;       ///< the cache of cold_work
    std::string source;      ///< where they came from, in words
    bool calibrated = true;  ///< false: defaults(), an order-of-magnitude guess
    std::string gpu;         ///< the GPU the timings were measured on (calibrate --gpu)
    std::string measuredAt;  ///< the commit(s) that measured them (calibrate --measured-at)

    /// Order-of-magnitude defaults for a current desktop RTX GPU, for use
    /// before calibration: 50 G threads/s, 2 G warp steps/s, 2 G rays/s,
    /// 5 G BLAS entries/s, 1 G any-hits/s, 500 GB/s. Uncalibrated: only on request.
    static CostCoefficients defaults();
    /// Reads a file written by save() / `accretion calibrate`; throws InputError naming it.
    static CostCoefficients load(const std::string& path);
    /// The calibration committed with the project (bench/gpu/results/fit/
    /// coefficients_h100.json, compiled in): what `accretion cost` prices with
    /// by default.
    static CostCoefficients committed();
    /// By gpu.coefficients: "" the committed calibration, "uncalibrated" the
    /// defaults, else the file.
    static CostCoefficients forSetting(const std::string& setting);
    /// The parsed JSON of a coefficients file; `name` names it in errors.
    static CostCoefficients fromJson(const nlohmann::json& j, const std::string& name);
    nlohmann::json toJson() const;

    /// With the shared coefficients.
    double predictMs(const CostFeatures& f) const;
    /// With the pass's own coefficients when there are any, else those of
    /// its proxy (kPasses' costProxy), else the shared ones.
    double predictMs(Pass pass, const CostFeatures& f) const;
};

/// Non-negative least squares, min |A x - b| subject to x >= 0 (Lawson &
/// Hanson's active-set method).
std::vector<double> nonNegativeLeastSquares(const std::vector<CostFeatures>& A, const std::vector<double>& b);

/// One pass of one configuration: its counters and, for calibration, the measured time.
struct CostRow {
    std::string config;
    PassRun pass;
    CostFeatures features{};
    double measuredMs = 0.0;
    double workingSetBytes = 0.0;  ///< PassReport::workingSetBytes (cold_work is recomputed from it for a cache)
    std::string origin;            ///< "FILE:LINE" of the counter row (readCounterCsv)
    /// The runs of the pass its counters hold: more than one where one
    /// timing named the pass for all its runs (joinTimings summed them).
    std::uint32_t runs = 1;
};

/// counters.csv as `accretion cost` writes it (config,pass,<features...>,
/// working_set_bytes,predicted_ms): a column of another name (a misspelt
/// counter) and a second row of one (config, pass) are refused, naming the
/// file and line.
std::vector<CostRow> readCounterCsv(const std::string& path);
/// timings.csv: config,pass,ms (one row per pass per configuration, as
/// exported from Nsight); joined to the counters on (config, pass). Two
/// counter rows of one (config, pass), from one file or two, are refused:
/// a timing must name the one row it times. A pass that ran several times
/// in the frame (spatialResampling[2] ...) timed once under its name alone,
/// as the twin times the loop of spatial iterations, times all its runs:
/// their counters are summed into one row (features added, the largest
/// working set) that the timing joins. Where a later run is timed on its
/// own, each run joins its own timing.
void joinTimings(const std::string& path, std::vector<CostRow>& rows);

struct Calibration {
    CostCoefficients coefficients;
    std::vector<CostRow> rows;
    std::vector<double> predictedMs;
    double rmsMs = 0.0, r2 = 0.0, maxRelativeError = 0.0;
    nlohmann::json toJson() const;
};

/// Fits the coefficients to the measured times (NNLS, features rescaled).
Calibration calibrate(const std::vector<CostRow>& rows, CostModelForm form = CostModelForm::shared);

/// The fit judged on configurations it has not seen: the configurations
/// split at random (a seeded Fisher-Yates), `fraction` of them fitted, the
/// rest predicted; per pass the median and worst relative error, and per
/// predicted configuration its frame (the sum of its timed passes) and its
/// spatial reuse run more than once (the sum of its spatialResampling or
/// resampleWorldNeighbours runs, for configurations with a second run).
struct HoldoutError {
    std::optional<Pass> pass;  ///< nullopt: all passes
    std::string label() const { return pass ? std::string(passName(*pass)) : std::string("all passes"); }
    std::size_t rows = 0;
    double median = 0.0, worst = 0.0;
    std::string worstConfig;
};
struct Holdout {
    CostModelForm form;
    std::vector<std::string> fitted, predicted;  ///< configurations
    std::vector<HoldoutError> passes;           ///< and last, "all passes"
    HoldoutError frames;                        ///< the predicted configurations' frames
    HoldoutError iteratedSpatial;               ///< their spatial reuse runs (spatialResampling or resampleWorldNeighbours) summed, where there are 2 or more
    std::vector<CostRow> rows;                  ///< the predicted rows (measuredMs) ...
    std::vector<double> predictedMs;            ///< ... and their predictions
    nlohmann::json toJson() const;
};
Holdout holdout(const std::vector<CostRow>& rows, CostModelForm form, double fraction, std::uint64_t seed);

}  // namespace accretion
