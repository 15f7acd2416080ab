// accretion calibrate: fit the cost model's coefficients (non-negative
// least squares) to GPU timings the user measured, one row per pass per
// configuration, against the counters `accretion cost` wrote.
#include <map>
#include <memory>
#include <optional>

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
    CostModelForm form = CostModelForm::shared;
    std::optional<double> holdout;   ///< fraction of the configurations fitted; the rest predicted
    std::uint64_t splitSeed = 1;
};

/// Held-out errors of both forms side by side, per pass.
nlohmann::json reportHoldout(const std::vector<CostRow>& rows, double fraction, std::uint64_t seed) {
    const Holdout a = holdout(rows, CostModelForm::shared, fraction, seed);
    const Holdout b = holdout(rows, CostModelForm::per_pass, fraction, seed);
    fmt::print("held out: fitted on {} configurations, predicted {} (split seed {}); relative error of the predicted:\n",
               a.fitted.size(), a.predicted.size(), seed);
    fmt::print("{:<22} {:>5}  {:>14} {:>14}  {:>14} {:>14}\n", "pass", "rows", "shared median", "shared worst",
               "per_pass median", "per_pass worst");
    for (std::size_t k = 0; k < a.passes.size() && k < b.passes.size(); ++k)
        fmt::print("{:<22} {:>5}  {:>13.1f}% {:>13.1f}%  {:>14.1f}% {:>13.1f}%\n", a.passes[k].pass, a.passes[k].rows,
                   100 * a.passes[k].median, 100 * a.passes[k].worst, 100 * b.passes[k].median, 100 * b.passes[k].worst);
    return {{"fraction", fraction}, {"split_seed", seed}, {"shared", a.toJson()}, {"per_pass", b.toJson()}};
}

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
    const Calibration c = calibrate(rows, args.form);
    fmt::print("fitted on {} timed passes (non-negative least squares, form {}):\n", rows.size(), costModelFormName(args.form));
    for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
        fmt::print("  {:<14} {:>12.6g} ns\n", kCostFeatures[k], c.coefficients.ns[k]);
    for (const auto& [pass, ns] : c.coefficients.perPass) {
        std::string line;
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
            if (ns[k] > 0.0) line += fmt::format(" {} {:.4g}", kCostFeatures[k], ns[k]);
        fmt::print("  {:<22} ns:{}\n", pass, line);
    }
    fmt::print("{:<14} {:<22} {:>12} {:>12} {:>12}\n", "config", "pass", "measured ms", "predicted", "residual");
    for (std::size_t i = 0; i < c.rows.size(); ++i)
        fmt::print("{:<14} {:<22} {:>12.4f} {:>12.4f} {:>+12.4f}\n", c.rows[i].config, c.rows[i].pass, c.rows[i].measuredMs,
                   c.predictedMs[i], c.predictedMs[i] - c.rows[i].measuredMs);
    fmt::print("rms residual {:.4g} ms, R^2 {:.4f}, max relative error {:.1f}%\n", c.rmsMs, c.r2, 100.0 * c.maxRelativeError);
    nlohmann::json doc = c.toJson();
    doc["version"] = std::string(version());
    doc["counters"] = a.counters;
    doc["timings"] = a.timings;
    doc["form"] = costModelFormName(args.form);
    if (args.holdout) doc["holdout"] = reportHoldout(rows, *args.holdout, args.splitSeed);
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
    cmd->add_option("--form", args->form,
                    "Model form: shared (one coefficient per counter for all passes, least squares on ms) or per_pass "
                    "(each pass its own, launches included, on relative error)")
        ->transform(CLI::CheckedTransformer(std::map<std::string, CostModelForm>{{"shared", CostModelForm::shared},
                                                                                 {"per_pass", CostModelForm::per_pass}}));
    cmd->add_option("--holdout", args->holdout,
                    "Also fit both forms on this fraction of the configurations (at random) and report the relative "
                    "error of predicting the others, per pass")
        ->check(CLI::Range(0.05, 0.95));
    cmd->add_option("--split-seed", args->splitSeed, "Seed of --holdout's split");
    cmd->callback([args] { runCalibrate(*args); });
}

}  // namespace accretion::cmd
