#include "accretion/analysis/history_lag.h"

#include <algorithm>

#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "accretion/core/gbuffer_texel_layout.h"

namespace accretion {

namespace {

double rgbMean(const DVec3& v) { return (v.x + v.y + v.z) / 3.0; }

}  // namespace

HistoryLag::HistoryLag(std::vector<LagRule> rules) : rules_(std::move(rules)), kept_(rules_.size()) {}

void HistoryLag::addFrame(std::uint32_t frame, const std::vector<Vec3>& light, const std::vector<std::uint32_t>& particle) {
    if (light.size() != particle.size()) throw InternalError("HistoryLag::addFrame: light and particle differ in size");
    if (!lastParticle_.empty() && particle.size() != lastParticle_.size())
        throw InternalError("HistoryLag::addFrame: the frames differ in size");
    // Each visible particle's mean light over its pixels.
    std::unordered_map<std::uint32_t, std::pair<DVec3, std::uint32_t>> sums;
    for (std::size_t p = 0; p < light.size(); ++p) {
        if (particle[p] == kNoParticle) continue;
        auto& s = sums[particle[p]];
        s.first += DVec3(light[p]);
        ++s.second;
    }
    std::unordered_map<std::uint32_t, DVec3> mean;
    std::unordered_map<std::uint32_t, float> scalar;
    mean.reserve(sums.size());
    scalar.reserve(sums.size());
    for (const auto& [id, s] : sums) {
        mean[id] = s.first / double(s.second);
        scalar[id] = float(rgbMean(mean[id]));
    }
    // Each rule's histories: the particles in this frame's view, from theirs in the last.
    for (std::size_t r = 0; r < rules_.size(); ++r) {
        const LagRule& rule = rules_[r];
        std::unordered_map<std::uint32_t, Kept> next;
        next.reserve(mean.size());
        for (const auto& [id, value] : mean) {
            const auto last = kept_[r].find(id);
            if (last == kept_[r].end()) {
                next[id] = {value, 1};
                continue;
            }
            const std::uint32_t age = last->second.age + 1;
            const double w = rule.start == HistoryStart::mean ? std::max(1.0 - rule.history, 1.0 / double(age)) : 1.0 - rule.history;
            next[id] = {last->second.value + w * (value - last->second.value), age};  // a still light stays exactly itself
        }
        kept_[r] = std::move(next);
    }
    lastMean_ = std::move(mean);
    lastLight_ = light;
    lastParticle_ = particle;
    frames_.emplace_back(frame, std::move(scalar));
}

std::vector<LagOutcome> HistoryLag::outcomes() const {
    std::vector<LagOutcome> out;
    for (std::size_t r = 0; r < rules_.size(); ++r) {
        LagOutcome o;
        o.rule = rules_[r];
        o.particles = lastMean_.size();
        for (const auto& [id, k] : kept_[r]) o.fresh += k.age == 1;
        double rel = 0.0;
        for (const std::uint32_t id : lastParticle_) {
            if (id == kNoParticle) continue;
            const DVec3 now = lastMean_.at(id), history = kept_[r].at(id).value;
            o.now += rgbMean(now);
            o.history += rgbMean(history);
            for (int c = 0; c < 3; ++c) rel += (history[c] - now[c]) * (history[c] - now[c]) / (now[c] * now[c] + kRelMseEpsilon);
        }
        o.relMSE = lastParticle_.empty() ? 0.0 : rel / (3.0 * double(lastParticle_.size()));
        out.push_back(o);
    }
    return out;
}

std::vector<LagTrendPoint> HistoryLag::trend() const {
    std::vector<LagTrendPoint> out;
    if (frames_.empty()) return out;
    const auto& last = frames_.back().second;
    std::size_t lit = 0;
    for (const std::uint32_t id : lastParticle_) lit += id != kNoParticle;
    for (const auto& [frame, means] : frames_) {
        double then = 0.0, now = 0.0;
        std::size_t tracked = 0;
        for (const std::uint32_t id : lastParticle_) {
            if (id == kNoParticle) continue;
            const auto t = means.find(id);
            if (t == means.end()) continue;
            then += t->second;
            now += last.at(id);
            ++tracked;
        }
        out.push_back({frame, now > 0.0 ? then / now : 0.0, lit ? double(tracked) / double(lit) : 0.0});
    }
    return out;
}

}  // namespace accretion
