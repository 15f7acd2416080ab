#include <cmath>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "accretion/io/report_table.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CompareArgs {
    std::string image, reference, layer;
    bool json = false;
    bool allowNonFinite = false;  ///< --allow-nonfinite: measure the finite pixels, exit 0
};

/// "image.exr" or "reference ref.exr": which of them holds a non-finite value at pixel p.
std::string nonFiniteOwner(const CompareArgs& a, const RgbLayer& x, std::size_t p) {
    const Vec3& v = x.rgb[p];
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? "the reference " + a.reference : a.image;
}

void runCompare(const CompareArgs& a) {
    const RgbLayer x = readExrLayer(a.image, a.layer);
    const RgbLayer ref = readExrLayer(a.reference, a.layer);
    if (x.width != ref.width || x.height != ref.height)
        throw InputError(fmt::format("{}: {}x{} pixels, but the reference {} is {}x{}", a.image, x.width, x.height,
                                     a.reference, ref.width, ref.height));
    const ErrorMetrics m = computeErrors(x.rgb, ref.rgb);
    auto hidden = [](const char* key) { return Column{key, "", 0, "{}", "{}", false}; };
    Table t({hidden("image"), hidden("reference"), hidden("layer"), {"relMSE", "relMSE", 0, "{:.9g}"},
             {"MSE", "MSE", 0, "{:.9g}"}, {"MAPE", "MAPE", 0, "{:.9g}"}, hidden("epsilon"), hidden("pixels"), hidden("nonfinite_pixels")});
    t.add({a.image, a.reference, a.layer.empty() ? "RGB" : a.layer, m.relMSE, m.MSE, m.MAPE, kRelMseEpsilon,
           std::uint64_t(m.pixels), std::uint64_t(m.nonFinite)});
    if (m.nonFinite > 0) {
        const std::size_t p = m.firstNonFinite;
        const std::string msg = fmt::format("{} of {} pixels are NaN or infinite (first at x={} y={}, in {}) and left out",
                                            m.nonFinite, x.rgb.size(), p % x.width, p / x.width, nonFiniteOwner(a, x, p));
        if (!a.allowNonFinite || m.pixels == 0)
            throw InputError(fmt::format("{}: {}{}", a.image, msg,
                                         m.pixels == 0 ? ": no finite pixel is left to measure"
                                                       : "; give --allow-nonfinite to measure the rest"));
        fmt::print(stderr, "accretion: warning: {}\n", msg);
    }
    fmt::print("{}", a.json ? t.json()[0].dump(2) + "\n" : t.keyValues());
}

}  // namespace

void addCompareCommand(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an EXR against a reference EXR (the second image)");
    cmd->add_option("image", args->image, "Image (EXR)")->required();
    cmd->add_option("reference", args->reference, "Reference (EXR)")->required();
    cmd->add_option("--layer", args->layer, "Channels compared: RGB (default) or a layer such as Lr");
    cmd->add_flag("--json", args->json, "Machine-readable output");
    cmd->add_flag("--allow-nonfinite", args->allowNonFinite,
                  "Measure the finite pixels when some are NaN or infinite (counted, first one located; else exit 1)");
    cmd->footer("relMSE = mean (x-ref)^2/(ref^2+1e-2); MSE = mean (x-ref)^2; MAPE = mean |x-ref|/(|ref|+1e-2);\n"
                "means over pixels and RGB channels.");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace accretion::cmd
