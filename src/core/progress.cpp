#include "accretion/core/progress.h"

#include <algorithm>
#include <exception>

#include <unistd.h>

#include <fmt/core.h>

namespace accretion {

Progress::Progress(std::string label, std::uint64_t total, bool quiet) : Progress(std::move(label), total, quiet, Output{}) {}

Progress::Progress(std::string label, std::uint64_t total, bool quiet, Output output)
    : label_(std::move(label)), total_(total ? total : 1), quiet_(quiet), terminal_(::isatty(::fileno(output.file)) == 1),
      out_(output.file),
      interval_(output.intervalSeconds >= 0.0 ? output.intervalSeconds : terminal_ ? 0.5 : 5.0),
      uncaught_(std::uncaught_exceptions()), start_(std::chrono::steady_clock::now()), lastPrint_(start_) {}

Progress::~Progress() {
    if (finished_) return;
    if (std::uncaught_exceptions() > uncaught_) {  // stopped: say where, never "100%"
        if (quiet_) return;
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        const double frac = std::min(1.0, double(done_.load()) / double(total_));
        fmt::print(out_, "{}{}: interrupted at {:.0f}% ({:.1f} s){}\n", terminal_ ? "\r" : "", label_, 100.0 * frac,
                   elapsed, terminal_ ? "          " : "");
        std::fflush(out_);
        return;
    }
    finish();
}

void Progress::advance(std::uint64_t n) {
    const std::uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
    if (quiet_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - lastPrint_ < interval_) return;
    std::unique_lock lock(mutex_, std::try_to_lock);
    if (!lock.owns_lock() || now - lastPrint_ < interval_) return;
    lastPrint_ = now;
    print(done, false);
}

void Progress::finish() {
    finished_ = true;
    if (!quiet_) print(total_, true);
}

void Progress::print(std::uint64_t done, bool final) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double frac = std::min(1.0, double(done) / double(total_));
    const char* begin = terminal_ ? "\r" : "";
    if (final) {
        fmt::print(out_, "{}{}: 100% ({:.2f} s){}\n", begin, label_, elapsed, terminal_ ? "          " : "");
    } else {
        const double eta = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
        fmt::print(out_, "{}{}: {:3.0f}% ({:.1f} s, eta {:.1f} s){}", begin, label_, 100.0 * frac, elapsed, eta,
                   terminal_ ? "   " : "\n");
    }
    std::fflush(out_);
}

}  // namespace accretion
