#include "accretion/analysis/history_lag.h"

#include <algorithm>
#include <unordered_set>

#include "accretion/analysis/error_anatomy.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "accretion/core/gbuffer_texel_layout.h"

namespace accretion {

namespace {

double rgbMean(const DVec3& v) { return (v.x + v.y + v.z) / 3.0; }

/// Each visible particle's mean of `light` over its pixels.
std::unordered_map<std::uint32_t, DVec3> particleMeans(const std::vector<Vec3>& light, const std::vector<std::uint32_t>& particle) {
    std::unordered_map<std::uint32_t, DVec3> mean;
    for (const auto& [id, m] : particlePixels(light, particle)) mean[id] = m.mean();
    return mean;
}

}  // namespace

HistoryLag::HistoryLag(std::vector<LagRule> rules) : rules_(std::move(rules)), kept_(rules_.size()) {}

void HistoryLag::addFrame(std::uint32_t frame, const std::vector<Vec3>& light, const std::vector<std::uint32_t>& particle,
                          const std::vector<Vec3>& whole) {
    if (light.size() != particle.size() || (!whole.empty() && whole.size() != light.size()))
        throw InternalError("HistoryLag::addFrame: light, particle and whole differ in size");
    if (!lastParticle_.empty() && particle.size() != lastParticle_.size())
        throw InternalError("HistoryLag::addFrame: the frames differ in size");
    std::unordered_map<std::uint32_t, DVec3> mean = particleMeans(light, particle);
    std::unordered_map<std::uint32_t, float> scalar;
    scalar.reserve(mean.size());
    for (const auto& [id, m] : mean) scalar[id] = float(rgbMean(m));
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
    lastWhole_ = whole.empty() ? mean : particleMeans(whole, particle);
    lastMean_ = std::move(mean);
    lastParticle_ = particle;
    frames_.emplace_back(frame, std::move(scalar));
}

std::vector<LagOutcome> HistoryLag::outcomes(const std::vector<bool>& measured) const {
    if (!measured.empty() && measured.size() != lastParticle_.size()) throw InternalError("HistoryLag::outcomes: a mask of another size");
    std::vector<LagOutcome> out;
    for (std::size_t r = 0; r < rules_.size(); ++r) {
        LagOutcome o;
        o.rule = rules_[r];
        std::unordered_set<std::uint32_t> seen;  // the particles the measured pixels see
        double rel = 0.0;
        std::size_t pixels = 0;
        for (std::size_t p = 0; p < lastParticle_.size(); ++p) {
            if (!measured.empty() && !measured[p]) continue;
            ++pixels;
            const std::uint32_t id = lastParticle_[p];
            if (id == kNoParticle) continue;
            if (seen.insert(id).second) o.fresh += kept_[r].at(id).age == 1;
            const DVec3 now = lastMean_.at(id), history = kept_[r].at(id).value, whole = lastWhole_.at(id);
            o.now += rgbMean(now);
            o.history += rgbMean(history);
            o.whole += rgbMean(whole);
            for (int c = 0; c < 3; ++c) rel += (history[c] - now[c]) * (history[c] - now[c]) / (whole[c] * whole[c] + kRelMseEpsilon);
        }
        o.particles = seen.size();
        o.relMSE = pixels ? rel / (3.0 * double(pixels)) : 0.0;
        out.push_back(o);
    }
    return out;
}

std::vector<LagTrendPoint> HistoryLag::trend(const std::vector<bool>& measured) const {
    std::vector<LagTrendPoint> out;
    if (frames_.empty()) return out;
    if (!measured.empty() && measured.size() != lastParticle_.size()) throw InternalError("HistoryLag::trend: a mask of another size");
    const auto& last = frames_.back().second;
    std::vector<std::uint32_t> lit;  // the measured pixels' particles
    for (std::size_t p = 0; p < lastParticle_.size(); ++p)
        if ((measured.empty() || measured[p]) && lastParticle_[p] != kNoParticle) lit.push_back(lastParticle_[p]);
    for (const auto& [frame, means] : frames_) {
        double then = 0.0, now = 0.0;
        std::size_t tracked = 0;
        for (const std::uint32_t id : lit) {
            const auto t = means.find(id);
            if (t == means.end()) continue;
            then += t->second;
            now += last.at(id);
            ++tracked;
        }
        out.push_back({frame, now > 0.0 ? then / now : 0.0, lit.empty() ? 0.0 : double(tracked) / double(lit.size())});
    }
    return out;
}

}  // namespace accretion
