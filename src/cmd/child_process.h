#pragma once
// Commands that run this same executable as a child process (batch's jobs,
// tune's measurements): its output to a log, in its own process group.
#include <filesystem>
#include <string>
#include <vector>

#include <sys/types.h>

namespace accretion {
class StopSignal;
}

namespace accretion::cmd {

/// Starts /proc/self/exe with argv (argv[0] included), stdout and stderr to
/// `log`, in a process group of its own: a terminal's Ctrl-C reaches the
/// parent only, which decides what the child gets.
pid_t spawnSelf(const std::vector<std::string>& argv, const std::filesystem::path& log);

/// spawnSelf, then waits: the child's exit code (128 + n when signal n ended
/// it). With `stop`, a SIGINT or SIGTERM the parent receives meanwhile is
/// forwarded to the child (forwardStop) and the child is still waited for,
/// so that no measurement outlives the command that asked for it.
int runSelf(const std::vector<std::string>& argv, const std::filesystem::path& log, const StopSignal* stop = nullptr);

/// The one way a stop request reaches a child: `signal` to its whole process
/// group (spawnSelf makes one per child), so its own children stop too.
void forwardStop(pid_t child, int signal);

/// The last non-empty line of a log (a failed child's error; progress lines
/// that end in \r count by their last part).
std::string lastLine(const std::filesystem::path& log);

}  // namespace accretion::cmd
