#include "accretion/core/pass_timer.h"

namespace accretion {

void PassTimer::add(Pass pass, std::chrono::steady_clock::duration d) {
    seconds_[index(pass)] += std::chrono::duration<double>(d).count();
    ++runs_[index(pass)];
}

std::vector<std::pair<Pass, double>> PassTimer::all() const {
    std::vector<std::pair<Pass, double>> out;
    for (const PassInfo& p : kPasses)
        if (ran(p.pass)) out.emplace_back(p.pass, seconds(p.pass));
    return out;
}

}  // namespace accretion
