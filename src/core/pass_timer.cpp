#include "accretion/core/pass_timer.h"

namespace accretion {

std::optional<Pass> parsePass(std::string_view name) {
    const std::size_t bracket = name.find('[');
    const std::string_view family = name.substr(0, bracket);
    if (bracket != std::string_view::npos) {  // [N], N a positive number
        const std::string_view n = name.substr(bracket + 1);
        if (n.size() < 2 || n.back() != ']' || n.front() == '0') return std::nullopt;
        for (const char c : n.substr(0, n.size() - 1))
            if (c < '0' || c > '9') return std::nullopt;
    }
    for (std::size_t k = 0; k < kPassNames.size(); ++k)
        if (kPassNames[k] == family) return static_cast<Pass>(k);
    return std::nullopt;
}

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
