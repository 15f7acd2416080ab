#pragma once
#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace accretion {

/// Thread-safe progress line on stderr, rate-limited; silent when quiet.
class Progress {
public:
    Progress(std::string label, std::uint64_t total, bool quiet);
    ~Progress();
    /// Record n more units done (any thread).
    void advance(std::uint64_t n);
    /// Print the final 100% line.
    void finish();

private:
    void print(std::uint64_t done, bool final);

    std::string label_;
    std::uint64_t total_;
    bool quiet_;
    bool finished_ = false;
    std::atomic<std::uint64_t> done_{0};
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, lastPrint_;
};

}  // namespace accretion
