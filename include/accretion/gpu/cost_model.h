#pragma once
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "accretion/gpu/gpu_report.h"

namespace accretion {

/// The counters a pass's predicted time is linear in (docs/MODEL.md section 6).
inline constexpr std::array<std::string_view, 6> kCostFeatures = {"threads", "warp_steps", "rays",
                                                                   "blas_entries", "any_hits", "bytes"};
using CostFeatures = std::array<double, kCostFeatures.size()>;

CostFeatures costFeatures(const PassReport& pass);

/// Nanoseconds per unit of each feature: predicted time = sum coefficient x counter.
struct CostCoefficients {
    CostFeatures ns{};
    std::string source;  ///< "defaults (uncalibrated)" or the file read

    /// Order-of-magnitude defaults for a current desktop RTX GPU, for use
    /// before calibration: 50 G threads/s, 2 G warp steps/s, 2 G rays/s,
    /// 5 G BLAS entries/s, 1 G any-hits/s, 500 GB/s.
    static CostCoefficients defaults();
    /// Reads a file written by save() / `accretion calibrate`; throws InputError naming it.
    static CostCoefficients load(const std::string& path);
    nlohmann::json toJson() const;

    double predictMs(const CostFeatures& f) const;
};

/// Non-negative least squares, min |A x - b| subject to x >= 0 (Lawson &
/// Hanson's active-set method).
std::vector<double> nonNegativeLeastSquares(const std::vector<CostFeatures>& A, const std::vector<double>& b);

/// One pass of one configuration: its counters and, for calibration, the measured time.
struct CostRow {
    std::string config, pass;
    CostFeatures features{};
    double measuredMs = 0.0;
};

/// counters.csv as `accretion cost` writes it (config,pass,<features...>).
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

/// Fits the coefficients to the measured times (NNLS in ms, rescaled per feature).
Calibration calibrate(const std::vector<CostRow>& rows);

}  // namespace accretion
