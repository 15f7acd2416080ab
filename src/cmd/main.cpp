// accretion: CPU reference renderer and GPU-cost simulator for ray-traced
// particle lighting. Subcommands: render, particles.
#include <algorithm>
#include <cstdio>
#include <new>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/stop_signal.h"
#include "accretion/core/version.h"
#include "commands.h"

int main(int argc, char** argv) {
    CLI::App app{"accretion: reference renderer and GPU-cost simulator for ray-traced particle lighting"};
    app.set_version_flag("--version", std::string(accretion::version()));
    app.require_subcommand(1);
    accretion::cmd::addRenderCommand(app);
    accretion::cmd::addParticlesCommand(app);
    accretion::cmd::addCompareCommand(app);
    accretion::cmd::addConvergeCommand(app);
    accretion::cmd::addBiasCommand(app);
    accretion::cmd::addCostCommand(app);
    accretion::cmd::addCalibrateCommand(app);
    accretion::cmd::addPlanCommand(app);
    accretion::cmd::addEstimatorsCommand(app);
    accretion::cmd::addPassesCommand(app);
    accretion::cmd::addMergeCommand(app);
    accretion::cmd::addBatchCommand(app);
    accretion::cmd::addCamerasCommand(app);
    accretion::cmd::addImportGpuCommand(app);
    accretion::cmd::addTuneCommand(app);
    accretion::cmd::addLagCommand(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        // One line, exit 1, like every other user error.
        std::string msg = e.what();
        std::replace(msg.begin(), msg.end(), '\n', ' ');
        fmt::print(stderr, "accretion: error: command line: {} (see --help)\n", msg);
        return 1;
    } catch (const accretion::cmd::BatchFailed&) {
        return 4;  // the summary says which jobs failed
    } catch (const accretion::Interrupted& e) {
        return 128 + e.signal;  // checkpoint written; the shell's convention for a signal
    } catch (const accretion::InputError& e) {
        fmt::print(stderr, "accretion: error: {}\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        // The run's estimate (checked before it starts) missed: still the
        // user's request, too large for this machine.
        fmt::print(stderr, "accretion: error: out of memory: the run needs more memory than this machine can give; "
                           "lower the resolution, particle count or samples\n");
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "accretion: internal error: {}\n", e.what());
        return 3;
    }
    return 0;
}
