#include "accretion/core/pass.h"

#include <charconv>

namespace accretion {

std::string PassRun::label() const {
    std::string out(passName(pass));
    if (run > 1) out += "[" + std::to_string(run) + "]";
    return out;
}

std::optional<PassRun> parsePassRun(std::string_view label) {
    const std::size_t bracket = label.find('[');
    const std::string_view family = label.substr(0, bracket);
    PassRun out;
    if (bracket != std::string_view::npos) {  // [N], N >= 2 written without leading zeros
        const std::string_view n = label.substr(bracket + 1);
        if (n.size() < 2 || n.back() != ']' || n.front() == '0' || n.front() == '+') return std::nullopt;
        const std::string_view digits = n.substr(0, n.size() - 1);
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), out.run);
        if (ec != std::errc{} || end != digits.data() + digits.size() || out.run < 2) return std::nullopt;
    }
    for (const PassInfo& p : kPasses)
        if (p.name == family) {
            out.pass = p.pass;
            return out;
        }
    return std::nullopt;
}

std::optional<Pass> parsePass(std::string_view name) {
    const std::optional<PassRun> run = parsePassRun(name);
    return run ? std::optional<Pass>(run->pass) : std::nullopt;
}

std::string passNameList() {
    std::string out;
    for (const PassInfo& p : kPasses) out += (out.empty() ? "" : ", ") + std::string(p.name);
    return out;
}

}  // namespace accretion
