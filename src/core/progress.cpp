#include "accretion/core/progress.h"

#include <cstdio>

#include <fmt/core.h>

namespace accretion {

Progress::Progress(std::string label, std::uint64_t total, bool quiet)
    : label_(std::move(label)), total_(total ? total : 1), quiet_(quiet),
      start_(std::chrono::steady_clock::now()), lastPrint_(start_) {}

Progress::~Progress() {
    if (!finished_) finish();
}

void Progress::advance(std::uint64_t n) {
    const std::uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (quiet_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - lastPrint_ < std::chrono::milliseconds(500)) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || now - lastPrint_ < std::chrono::milliseconds(500)) return;
    lastPrint_ = now;
    print(done, false);
}

void Progress::finish() {
    finished_ = true;
    if (!quiet_) print(total_, true);
}

void Progress::print(std::uint64_t done, bool final) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double frac = static_cast<double>(done) / static_cast<double>(total_);
    if (final) {
        fmt::print(stderr, "\r{}: 100% ({:.2f} s)          \n", label_, elapsed);
    } else {
        const double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
        fmt::print(stderr, "\r{}: {:3.0f}% ({:.1f} s, eta {:.1f} s)   ", label_, 100.0 * frac, elapsed, eta);
    }
    std::fflush(stderr);
}

}  // namespace accretion
