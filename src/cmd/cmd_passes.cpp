// accretion passes: the pass table (core/pass.h) as markdown, or as JSON for
// the scripts, which take every pass name from here and from nowhere else.
#include <memory>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "accretion/core/pass.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

std::string_view gridName(PassGrid g) {
    switch (g) {
        case PassGrid::host: return "host";
        case PassGrid::clusters: return "clusters";
        case PassGrid::pixels: return "pixels";
        case PassGrid::entries: return "entries";
    }
    return "host";
}

std::string_view launchName(PassLaunch l) { return l == PassLaunch::row ? "row" : "tiles"; }

nlohmann::json passesJson() {
    nlohmann::json passes = nlohmann::json::array();
    for (const PassInfo& p : kPasses)
        passes.push_back({{"name", p.name},
                          {"parent", isNested(p.pass) ? nlohmann::json(passName(p.parent)) : nlohmann::json(nullptr)},
                          {"grid", gridName(p.grid)},
                          {"launch", launchName(p.launch)},
                          {"cost_proxy", passName(p.costProxy)},
                          {"reads_lights", p.readsLights},
                          {"reads", p.reads}});
    return {{"passes", passes}};
}

void printPasses(bool json) {
    if (json) {
        fmt::print("{}\n", passesJson().dump(2));
        return;
    }
    fmt::print("| pass | timed inside | one GPU thread per | launched as | priced as | reads |\n|---|---|---|---|---|---|\n");
    for (const PassInfo& p : kPasses)
        fmt::print("| `{}` | {} | {} | {} | {} | {} |\n", p.name, isNested(p.pass) ? passName(p.parent) : "-", gridName(p.grid),
                   launchName(p.launch), p.costProxy == p.pass ? "itself" : passName(p.costProxy), p.reads);
}

}  // namespace

void addPassesCommand(CLI::App& app) {
    auto json = std::make_shared<bool>(false);
    CLI::App* cmd = app.add_subcommand("passes", "Print the passes of a frame (the pass table), as markdown or --json");
    cmd->add_flag("--json", *json, "JSON: {\"passes\": [{name, parent, grid, launch, cost_proxy, reads_lights, reads}, ...]}");
    cmd->callback([json] { printPasses(*json); });
}

}  // namespace accretion::cmd
