// accretion calibrate: fit the cost model's coefficients (non-negative
// least squares) to GPU timings the user measured, one row per pass per
// configuration, against the counters `accretion cost` wrote.
#include <memory>

#include <fmt/core.h>

#include "accretion/core/version.h"
#include "accretion/gpu/cost_model.h"
#include "accretion/io/stats_writer.h"
#include "accretion/core/output_guard.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CalibrateArgs {
    std::vector<std::string> files;  ///< counters.csv... timings.csv
    std::string output = "out/cost_coefficients.json";
};

void runCalibrate(const CalibrateArgs& args) {
    struct {
        std::vector<std::string> counters;
        std::string timings, output;
    } a{{args.files.begin(), args.files.end() - 1}, args.files.back(), args.output};
    OutputGuard guard;  // the fit never replaces the measurements it reads
    for (const std::string& f : args.files) guard.addInput(f);
    guard.check(a.output, "-o");
    std::vector<CostRow> rows;
    for (const std::string& file : a.counters) {
        std::vector<CostRow> r = readCounterCsv(file);
        rows.insert(rows.end(), r.begin(), r.end());
    }
    joinTimings(a.timings, rows);
    const Calibration c = calibrate(rows);
    fmt::print("fitted on {} timed passes (non-negative least squares):\n", rows.size());
    for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
        fmt::print("  {:<14} {:>12.6g} ns\n", kCostFeatures[k], c.coefficients.ns[k]);
    fmt::print("{:<14} {:<22} {:>12} {:>12} {:>12}\n", "config", "pass", "measured ms", "predicted", "residual");
    for (std::size_t i = 0; i < c.rows.size(); ++i)
        fmt::print("{:<14} {:<22} {:>12.4f} {:>12.4f} {:>+12.4f}\n", c.rows[i].config, c.rows[i].pass, c.rows[i].measuredMs,
                   c.predictedMs[i], c.predictedMs[i] - c.rows[i].measuredMs);
    fmt::print("rms residual {:.4g} ms, R^2 {:.4f}, max relative error {:.1f}%\n", c.rmsMs, c.r2, 100.0 * c.maxRelativeError);
    nlohmann::json doc = c.toJson();
    doc["version"] = std::string(version());
    doc["counters"] = a.counters;
    doc["timings"] = a.timings;
    writeJson(a.output, doc);
    fmt::print("coefficients: {} (use with -D gpu.coefficients=\"{}\")\n", a.output, a.output);
}

}  // namespace

void addCalibrateCommand(CLI::App& app) {
    auto args = std::make_shared<CalibrateArgs>();
    CLI::App* cmd = app.add_subcommand("calibrate", "Fit the cost model to measured GPU timings (counters.csv timings.csv)");
    cmd->add_option("files", args->files,
                    "counters.csv [more counters.csv ...] timings.csv: counter CSVs from `accretion cost` "
                    "(config,pass,features...), then the measured timings (config,pass,ms)")
        ->required()
        ->expected(2, -1);
    cmd->add_option("-o,--output", args->output, "Coefficients JSON for gpu.coefficients");
    cmd->callback([args] { runCalibrate(*args); });
}

}  // namespace accretion::cmd
