// accretion estimators: the estimator table (scene/estimator_table.h) as
// markdown, the table docs/rendering.md carries.
#include <fmt/core.h>

#include "accretion/scene/estimator_table.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

std::string_view yesNo(bool b) { return b ? "yes" : "no"; }

std::string_view samplerName(LightSamplerKind k) {
    switch (k) {
        case LightSamplerKind::none: return "-";
        case LightSamplerKind::power: return "power table";
        case LightSamplerKind::tree: return "light tree";
    }
    return "-";
}

void printEstimators() {
    fmt::print("| estimator | what it computes | needs | resamples | reuse and history | unbiased | adaptive | twin |\n"
               "|---|---|---|---|---|---|---|---|\n");
    for (const EstimatorInfo& e : kEstimators)
        fmt::print("| `{}` | {} | {} | {} | {} | {} | {} | {} |\n", enumName(e.kind), e.summary,
                   e.drawsFromSource() ? "render.source's" : samplerName(e.sampler), yesNo(e.resampling), yesNo(e.reuse),
                   e.unbiased ? std::string_view("yes") : e.unbiasedWhen, yesNo(e.adaptive), yesNo(e.twin));
}

}  // namespace

void addEstimatorsCommand(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand("estimators", "Print the estimators of Lr and what each needs, as a markdown table");
    cmd->callback(printEstimators);
}

}  // namespace accretion::cmd
