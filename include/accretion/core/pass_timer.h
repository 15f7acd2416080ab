#pragma once
#include <array>
#include <chrono>
#include <utility>
#include <vector>

#include "accretion/core/pass.h"

namespace accretion {

/// Accumulated wall time per pass. A nested pass's time is also inside its
/// parent's (kPasses' parent column): the restir passes inside estimateLighting.
class PassTimer {
public:
    class Scope {
    public:
        Scope(PassTimer& timer, Pass pass) : timer_(timer), pass_(pass), start_(std::chrono::steady_clock::now()) {}
        ~Scope() { timer_.add(pass_, std::chrono::steady_clock::now() - start_); }
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;

    private:
        PassTimer& timer_;
        Pass pass_;
        std::chrono::steady_clock::time_point start_;
    };

    Scope scope(Pass pass) { return Scope(*this, pass); }
    void add(Pass pass, std::chrono::steady_clock::duration d);
    /// Seconds spent in a pass (0 if it never ran).
    double seconds(Pass pass) const { return seconds_[index(pass)]; }
    /// Whether a scope of the pass has closed (a pass may run in 0 s on a coarse clock).
    bool ran(Pass pass) const { return runs_[index(pass)] > 0; }
    /// How many scopes of the pass have closed.
    unsigned runs(Pass pass) const { return runs_[index(pass)]; }
    /// The passes that ran and their seconds, in table order.
    std::vector<std::pair<Pass, double>> all() const;

private:
    static std::size_t index(Pass p) { return static_cast<std::size_t>(p); }
    std::array<double, kPassCount> seconds_{};
    std::array<unsigned, kPassCount> runs_{};
};

}  // namespace accretion
