#include "accretion/core/pass_timer.h"

namespace accretion {

void PassTimer::add(std::string_view name, std::chrono::steady_clock::duration d) {
    const double s = std::chrono::duration<double>(d).count();
    auto it = seconds_.find(name);
    if (it == seconds_.end()) seconds_.emplace(std::string(name), s);
    else it->second += s;
}

double PassTimer::seconds(std::string_view name) const {
    auto it = seconds_.find(name);
    return it == seconds_.end() ? 0.0 : it->second;
}

double PassTimer::totalSeconds() const {
    double t = 0.0;
    for (const auto& [name, s] : seconds_) t += s;
    return t;
}

}  // namespace accretion
