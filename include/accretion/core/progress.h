#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

namespace accretion {

/// Thread-safe progress of one pass on stderr, by work done (the caller's
/// unit, e.g. hit pixels x samples), with an ETA from the rate of that work.
/// On a terminal one line redrawn with '\r' twice a second; elsewhere (a log
/// file, a pipe) whole lines every few seconds. Ends with "100%", or with
/// "interrupted at N%" when an exception (a signal's checkpoint, an error)
/// unwinds it first. Silent when quiet.
class Progress {
public:
    struct Output {
        std::FILE* file = stderr;
        double intervalSeconds = -1.0;  ///< between lines; < 0: 0.5 s on a terminal, 5 s elsewhere
    };
    Progress(std::string label, std::uint64_t total, bool quiet);
    Progress(std::string label, std::uint64_t total, bool quiet, Output output);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    /// Record n more units done (any thread).
    void advance(std::uint64_t n);
    /// Print the final 100% line.
    void finish();

private:
    void print(std::uint64_t done, bool final);

    std::string label_;
    std::uint64_t total_;
    bool quiet_;
    bool terminal_;
    std::FILE* out_;
    std::chrono::duration<double> interval_;
    bool finished_ = false;
    int uncaught_;  ///< exceptions in flight when constructed (a new one means unwinding)
    std::atomic<std::uint64_t> done_{0};
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, lastPrint_;
};

}  // namespace accretion
