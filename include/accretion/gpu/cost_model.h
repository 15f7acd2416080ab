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
/// scale 0.75 as at 0.5, for the same bytes asked). Counter CSVs without a
/// column read it as 0.
inline constexpr std::array<std::string_view, 32> kCostFeatures = {
    "threads",          "warp_steps",          "rays",                 "blas_entries",     "any_hits",
    "bytes",            "blas_levels",         "omm_lookups",          "dispatches",       "build_launches",
    "refit_launches",   "cold_work",           "accel_elements",       "accel_elements_1k", "accel_elements_32k",
    "build_primitives", "build_primitives_1k", "build_primitives_32k", "custom_builds",    "intersections",
    "tlas_levels",      "misses",              "segment_boxes",    "gathers",
    "sphere_refits",    "warp_segment_boxes",  "dispatch_path",
    "whole_segment_boxes", "warp_gathers",     "hit_warps",           "footprint_bytes",
    "tlas_instances_32k"};
inline constexpr std::size_t kBaseCostFeatures = 6;
inline constexpr std::size_t kColdWork = 11;
/// Whether feature k prices acceleration-structure builds: buildClusters is
/// fitted on these (and dispatches) alone, every other pass on the rest.
/// A pass's counters of the other kind are 0 or, like the build pass's
/// threads (one per cluster: collinear with its launches), say nothing of
/// its time, and a fit that gives them weight extrapolates badly.
constexpr bool isBuildFeature(std::size_t k) {
    constexpr std::string_view build[] = {"build_launches",   "refit_launches",      "accel_elements",
                                          "accel_elements_1k", "accel_elements_32k", "build_primitives",
                                          "build_primitives_1k", "build_primitives_32k", "custom_builds",
                                          "sphere_refits", "tlas_instances_32k"};
    for (std::string_view b : build)
        if (kCostFeatures[k] == b) return true;
    return false;
}
using CostFeatures = std::array<double, kCostFeatures.size()>;

/// The committed calibration (compiled in from this file of the source tree).
inline constexpr const char* kDefaultCoefficientsFile = "bench/gpu/results/fit/coefficients_h100.json";
/// Its text (generated/default_coefficients.cpp).
const char* defaultCoefficientsJson();

/// The cache the working-set term assumes before calibration (calibrate
/// chooses its own by cross-validation).
inline constexpr double kDefaultCacheBytes = 4.0 * 1024 * 1024;

/// The reads that miss a cache of `cacheBytes`: a traced pass's rays (else
/// its bytes) times the levels of a tree over the working set that the cache
/// cannot hold, log2(working set / cache), 0 when it fits. A BVH keeps its
/// top levels cached and misses below them; random reads of a table grow
/// their misses as it outgrows the cache (the H100 sweep of bench/gpu: 1M
/// particles cost the G-buffer 1.7x the rays of 100K, with fewer BLAS levels).
double coldWork(double rays, double bytes, double workingSetBytes, double cacheBytes);

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
};

/// counters.csv as `accretion cost` writes it (config,pass,<features...>,working_set_bytes).
std::vector<CostRow> readCounterCsv(const std::string& path);
/// timings.csv: config,pass,ms (one row per pass per configuration, as
/// exported from Nsight); joined to the counters on (config, pass).
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
/// rest predicted; per pass the median and worst relative error.
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
    std::vector<CostRow> rows;                  ///< the predicted rows (measuredMs) ...
    std::vector<double> predictedMs;            ///< ... and their predictions
    nlohmann::json toJson() const;
};
Holdout holdout(const std::vector<CostRow>& rows, CostModelForm form, double fraction, std::uint64_t seed);

}  // namespace accretion
