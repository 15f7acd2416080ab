#include "child_process.h"

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/stop_signal.h"

extern char** environ;

namespace accretion::cmd {

pid_t spawnSelf(const std::vector<std::string>& argv, const std::filesystem::path& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    std::vector<char*> args;
    for (const std::string& s : argv) args.push_back(const_cast<char*>(s.c_str()));
    args.push_back(nullptr);
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, "/proc/self/exe", &actions, &attr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
    if (rc != 0) throw InternalError(fmt::format("cannot start a child process: {}", std::strerror(rc)));
    return pid;
}

void forwardStop(pid_t child, int signal) { ::kill(-child, signal); }

int runSelf(const std::vector<std::string>& argv, const std::filesystem::path& log, const StopSignal* stop) {
    const pid_t pid = spawnSelf(argv, log);
    int status = 0, forwarded = 0;
    for (;;) {
        // Polled, not blocked on: a stop request is seen within 20 ms
        // whenever it comes, and forwarded once; the child is then waited for.
        if (stop && stop->pending() && !forwarded) forwardStop(pid, forwarded = stop->pending());
        const pid_t r = waitpid(pid, &status, stop ? WNOHANG : 0);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) throw InternalError(fmt::format("waiting for a child process: {}", std::strerror(errno)));
        if (r == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string lastLine(const std::filesystem::path& log) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line)) {
        const auto cr = line.rfind('\r');  // progress lines
        if (cr != std::string::npos) line = line.substr(cr + 1);
        if (!line.empty()) last = line;
    }
    return last;
}

}  // namespace accretion::cmd
