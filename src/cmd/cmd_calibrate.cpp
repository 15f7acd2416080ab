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
    std::string gpu, measuredAt;     ///< recorded in the coefficients: what measured the timings
};

/// Held-out errors of every form side by side, per pass.
nlohmann::json reportHoldout(const std::vector<CostRow>& rows, double fraction, std::uint64_t seed) {
    const CostModelForm forms[] = {CostModelForm::shared, CostModelForm::per_pass, CostModelForm::selected};
    std::vector<Holdout> h;
    for (CostModelForm f : forms) h.push_back(holdout(rows, f, fraction, seed));
    fmt::print("held out: fitted on {} configurations, predicted {} (split seed {}); relative error of the predicted:\n",
               h[0].fitted.size(), h[0].predicted.size(), seed);
    std::string header = fmt::format("{:<22} {:>5}", "pass", "rows");
    for (CostModelForm f : forms)
        header += fmt::format("  {:>15} {:>15}", fmt::format("{} median", costModelFormName(f)),
                              fmt::format("{} worst", costModelFormName(f)));
    fmt::print("{}\n", header);
    for (std::size_t k = 0; k < h[0].passes.size(); ++k) {
        std::string line = fmt::format("{:<22} {:>5}", h[0].passes[k].label(), h[0].passes[k].rows);
        for (const Holdout& x : h)
            if (k < x.passes.size()) line += fmt::format("  {:>14.1f}% {:>14.1f}%", 100 * x.passes[k].median, 100 * x.passes[k].worst);
        fmt::print("{}\n", line);
    }
    // A configuration's frame, and its spatial reuse run 2 or more times: each summed over its passes or runs.
    for (const auto& [name, of] : {std::pair{"frames", &Holdout::frames}, std::pair{"spatial, 2+ runs", &Holdout::iteratedSpatial}}) {
        std::string line = fmt::format("{:<22} {:>5}", name, (h[0].*of).rows);
        for (const Holdout& x : h) line += fmt::format("  {:>14.1f}% {:>14.1f}%", 100 * (x.*of).median, 100 * (x.*of).worst);
        fmt::print("{}\n", line);
    }
    nlohmann::json j = {{"fraction", fraction}, {"split_seed", seed}};
    for (std::size_t i = 0; i < h.size(); ++i) j[costModelFormName(forms[i])] = h[i].toJson();
    return j;
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
    if (args.form != CostModelForm::shared)
        fmt::print("  cache of cold_work: {:g} MiB (chosen by leave-one-configuration-out error)\n",
                   c.coefficients.cacheBytes / (1024.0 * 1024.0));
    for (const auto& [pass, ns] : c.coefficients.perPass) {
        std::string line;
        for (std::size_t k = 0; k < kCostFeatures.size(); ++k)
            if (ns[k] > 0.0) line += fmt::format(" {} {:.4g}", kCostFeatures[k], ns[k]);
        fmt::print("  {:<22} ns:{}\n", passName(pass), line);
    }
    fmt::print("{:<14} {:<22} {:>12} {:>12} {:>12}\n", "config", "pass", "measured ms", "predicted", "residual");
    for (std::size_t i = 0; i < c.rows.size(); ++i)
        fmt::print("{:<14} {:<22} {:>12.4f} {:>12.4f} {:>+12.4f}\n", c.rows[i].config, c.rows[i].pass.label(), c.rows[i].measuredMs,
                   c.predictedMs[i], c.predictedMs[i] - c.rows[i].measuredMs);
    fmt::print("rms residual {:.4g} ms, R^2 {:.4f}, max relative error {:.1f}%\n", c.rmsMs, c.r2, 100.0 * c.maxRelativeError);
    nlohmann::json doc = c.toJson();
    doc["version"] = std::string(version());
    doc["counters"] = a.counters;
    doc["timings"] = a.timings;
    doc["form"] = costModelFormName(args.form);
    if (!args.gpu.empty()) doc["gpu"] = args.gpu;
    if (!args.measuredAt.empty()) doc["measured_at"] = args.measuredAt;
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
                    "Model form: shared (one coefficient per counter for all passes, least squares on ms), per_pass "
                    "(each pass its own, launches included, on relative error) or selected (per_pass over the counters "
                    "chosen by leave-one-configuration-out error)")
        ->transform(CLI::CheckedTransformer(std::map<std::string, CostModelForm>{{"shared", CostModelForm::shared},
                                                                                 {"per_pass", CostModelForm::per_pass},
                                                                                 {"selected", CostModelForm::selected}}));
    cmd->add_option("--holdout", args->holdout,
                    "Also fit every form on this fraction of the configurations (at random) and report the relative "
                    "error of predicting the others, per pass")
        ->check(CLI::Range(0.05, 0.95));
    cmd->add_option("--split-seed", args->splitSeed, "Seed of --holdout's split");
    cmd->add_option("--gpu", args->gpu, "The GPU that measured the timings (recorded; `cost` names it)");
    cmd->add_option("--measured-at", args->measuredAt, "The commit(s) the timings and counters were measured at (recorded)");
    cmd->callback([args] { runCalibrate(*args); });
}

}  // namespace accretion::cmd
