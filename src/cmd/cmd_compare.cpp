#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CompareArgs {
    std::string image, reference, layer;
    bool json = false;
};

void runCompare(const CompareArgs& a) {
    const RgbLayer x = readExrLayer(a.image, a.layer);
    const RgbLayer ref = readExrLayer(a.reference, a.layer);
    if (x.width != ref.width || x.height != ref.height)
        throw InputError(fmt::format("{}: {}x{} pixels, but the reference {} is {}x{}", a.image, x.width, x.height,
                                     a.reference, ref.width, ref.height));
    const ErrorMetrics m = computeErrors(x.rgb, ref.rgb);
    if (a.json) {
        nlohmann::json j = {{"image", a.image},         {"reference", a.reference}, {"layer", a.layer.empty() ? "RGB" : a.layer},
                            {"relMSE", m.relMSE},       {"MSE", m.MSE},             {"MAPE", m.MAPE},
                            {"epsilon", kRelMseEpsilon}, {"pixels", m.pixels}};
        fmt::print("{}\n", j.dump(2));
        return;
    }
    fmt::print("relMSE {:.9g}\nMSE {:.9g}\nMAPE {:.9g}\n", m.relMSE, m.MSE, m.MAPE);
}

}  // namespace

void addCompareCommand(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an EXR against a reference EXR (the second image)");
    cmd->add_option("image", args->image, "Image (EXR)")->required();
    cmd->add_option("reference", args->reference, "Reference (EXR)")->required();
    cmd->add_option("--layer", args->layer, "Channels compared: RGB (default) or a layer such as Lr");
    cmd->add_flag("--json", args->json, "Machine-readable output");
    cmd->footer("relMSE = mean (x-ref)^2/(ref^2+1e-2); MSE = mean (x-ref)^2; MAPE = mean |x-ref|/(|ref|+1e-2);\n"
                "means over pixels and RGB channels.");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace accretion::cmd
