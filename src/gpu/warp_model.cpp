#include "accretion/gpu/warp_model.h"

#include <algorithm>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::vector<std::uint32_t> dispatchOrder(std::uint32_t width, std::uint32_t height, const WarpLayout& layout,
                                         PassLaunch launch) {
    if (launch == PassLaunch::row) {
        const std::size_t threads = std::size_t(width) * height;
        std::vector<std::uint32_t> order((threads + layout.warpSize - 1) / layout.warpSize * layout.warpSize, kIdleLane);
        for (std::size_t t = 0; t < threads; ++t) order[t] = std::uint32_t(t);
        return order;
    }
    const std::uint32_t gw = layout.groupWidth, gh = layout.groupHeight, ws = layout.warpSize;
    const std::uint32_t groupThreads = gw * gh;
    const std::uint32_t padded = (groupThreads + ws - 1) / ws * ws;
    const std::uint32_t gx = (width + gw - 1) / gw, gy = (height + gh - 1) / gh;
    std::vector<std::uint32_t> order;
    order.reserve(std::size_t(gx) * gy * padded);
    for (std::uint32_t by = 0; by < gy; ++by)
        for (std::uint32_t bx = 0; bx < gx; ++bx) {
            for (std::uint32_t t = 0; t < groupThreads; ++t) {
                const std::uint32_t x = bx * gw + t % gw, y = by * gh + t / gw;
                order.push_back(x < width && y < height ? y * width + x : kIdleLane);
            }
            order.insert(order.end(), padded - groupThreads, kIdleLane);
        }
    return order;
}

SimtStats simtStats(std::span<const std::uint32_t> order, std::span<const std::uint64_t> key,
                    std::span<const std::uint32_t> work, std::uint32_t warpSize) {
    SimtStats s;
    std::uint64_t keysSum = 0;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> lanes;  // (key, work) of one warp
    for (std::size_t w0 = 0; w0 < order.size(); w0 += warpSize) {
        lanes.clear();
        const std::size_t w1 = std::min(order.size(), w0 + warpSize);
        for (std::size_t i = w0; i < w1; ++i) {
            const std::uint32_t t = order[i];
            if (t == kIdleLane || work[t] == 0) continue;
            lanes.emplace_back(key[t], work[t]);
            s.laneWork += work[t];
        }
        if (lanes.empty()) continue;
        ++s.warps;
        // Each distinct key runs once, as long as its longest lane.
        std::sort(lanes.begin(), lanes.end());
        for (std::size_t i = 0; i < lanes.size();) {
            std::size_t j = i;
            std::uint32_t longest = 0;
            for (; j < lanes.size() && lanes[j].first == lanes[i].first; ++j) longest = std::max(longest, lanes[j].second);
            s.steps += longest;
            ++keysSum;
            i = j;
        }
    }
    if (s.steps > 0) {
        s.efficiency = double(s.laneWork) / (double(warpSize) * double(s.steps));
        s.activeThreadsPerStep = double(s.laneWork) / double(s.steps);
        s.distinctKeysPerWarp = double(keysSum) / double(s.warps);
    }
    return s;
}

std::vector<std::uint32_t> serReorder(std::span<const std::uint32_t> order, std::span<const std::uint64_t> sortKey,
                                      std::uint32_t window, std::uint32_t warpSize) {
    std::vector<std::uint32_t> active;
    active.reserve(order.size());
    for (std::uint32_t t : order)
        if (t != kIdleLane) active.push_back(t);
    std::vector<std::uint32_t> out;
    out.reserve(order.size());
    for (std::size_t b = 0; b < active.size(); b += window) {
        const auto first = active.begin() + std::ptrdiff_t(b);
        const auto last = active.begin() + std::ptrdiff_t(std::min(active.size(), b + window));
        std::stable_sort(first, last, [&](std::uint32_t a, std::uint32_t c) { return sortKey[a] < sortKey[c]; });
        out.insert(out.end(), first, last);
        while (out.size() % warpSize) out.push_back(kIdleLane);
    }
    return out;
}

SerKey SerKey::parse(const std::string& spec, std::uint32_t hintBits, const std::string& where) {
    std::string bad;
    const std::optional<SerKeySpec> key = parseSerKey(spec, bad);
    if (!key)
        throw InputError(fmt::format("{}: unknown SER key component '{}' (expected hit, type, cluster, hint)", where, bad));
    return SerKey(*key, hintBits);
}

std::uint64_t SerKey::of(const ThreadCounters& t) const {
    std::uint64_t key = 0;
    for (const SerComponent c : components) {
        switch (c) {
        case SerComponent::hit: key = (key << 1) | t.hit; break;
        case SerComponent::type: key = (key << 8) | t.type; break;
        case SerComponent::cluster: key = (key << 24) | (t.cluster & 0xffffffu); break;
        case SerComponent::hint:
            if (hintBits > 0) key = (key << hintBits) | (t.hint & ((1u << hintBits) - 1u));
            break;
        }
    }
    return key;
}

std::string SerKey::label() const {
    std::string s;
    for (const SerComponent c : components) s += (s.empty() ? "" : "+") + std::string(enumName(c));
    if (hintBits > 0 && std::find(components.begin(), components.end(), SerComponent::hint) != components.end())
        s += fmt::format("({} bits)", hintBits);
    return s;
}

SerReport serReport(const PassCounters& pass, const WarpLayout& layout, const SerKey& key, std::uint32_t window,
                    double reorderCost) {
    const std::size_t n = pass.threads.size();
    std::vector<std::uint64_t> branchKey(n), sortKey(n), one(n, 0);
    std::vector<std::uint32_t> branchWork(n), trips(n), boxes(n), nodes(n), gathers(n), hits(n);
    std::size_t active = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const ThreadCounters& t = pass.threads[i];
        branchKey[i] = t.branchKey();
        sortKey[i] = key.of(t);
        branchWork[i] = t.active;
        trips[i] = t.trips;
        boxes[i] = t.segmentBoxes;
        nodes[i] = t.nodeVisits;
        gathers[i] = t.gathers;
        hits[i] = t.hit;
        active += t.active;
    }
    const std::vector<std::uint32_t> before = dispatchOrder(pass.width, pass.height, layout, passInfo(pass.pass).launch);
    const std::vector<std::uint32_t> after = serReorder(before, sortKey, window, layout.warpSize);
    SerReport r;
    r.key = key.label();
    r.branchBefore = simtStats(before, branchKey, branchWork, layout.warpSize);
    r.branchAfter = simtStats(after, branchKey, branchWork, layout.warpSize);
    r.loopBefore = simtStats(before, one, trips, layout.warpSize);
    r.loopAfter = simtStats(after, one, trips, layout.warpSize);
    r.traversalBefore = simtStats(before, one, boxes, layout.warpSize);
    r.nodesBefore = simtStats(before, one, nodes, layout.warpSize);
    r.gathersBefore = simtStats(before, one, gathers, layout.warpSize);
    r.hitsBefore = simtStats(before, one, hits, layout.warpSize);
    r.distinctSortKeysBefore = simtStats(before, sortKey, branchWork, layout.warpSize).distinctKeysPerWarp;
    r.distinctSortKeysAfter = simtStats(after, sortKey, branchWork, layout.warpSize).distinctKeysPerWarp;
    r.reorderSteps = reorderCost * double(active) / double(layout.warpSize);
    const double stepsBefore = double(r.branchBefore.steps + r.loopBefore.steps);
    const double stepsAfter = double(r.branchAfter.steps + r.loopAfter.steps) + r.reorderSteps;
    r.predictedSpeedup = stepsAfter > 0.0 ? stepsBefore / stepsAfter : 1.0;
    return r;
}

}  // namespace accretion
