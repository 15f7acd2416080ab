#pragma once
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "accretion/core/pass.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/scene/settings.h"

namespace accretion {

inline constexpr std::uint32_t kIdleLane = std::numeric_limits<std::uint32_t>::max();

/// Thread groups of a 2D dispatch and the warps cut from them (docs/MODEL.md
/// section 6); a one-row launch uses only warpSize.
struct WarpLayout {
    std::uint32_t groupWidth = 8;
    std::uint32_t groupHeight = 8;
    std::uint32_t warpSize = 32;
};

/// The lanes of a width x height dispatch in hardware order; a warp is
/// `warpSize` consecutive entries. tiles: groups in row-major order, the
/// threads of a group row-major, each group padded to whole warps, threads
/// outside the grid (partial groups at the edges) kIdleLane. row: the
/// threads in record order (y x width + x), the last warp padded.
std::vector<std::uint32_t> dispatchOrder(std::uint32_t width, std::uint32_t height, const WarpLayout& layout,
                                         PassLaunch launch);

/// SIMT statistics of one region over a lane order.
struct SimtStats {
    double efficiency = 1.0;          ///< lane work / (warpSize x serialized steps)
    double activeThreadsPerStep = 0;  ///< mean active lanes per executed step (= efficiency x warpSize)
    double distinctKeysPerWarp = 0;   ///< mean over warps that execute the region
    std::uint64_t warps = 0;          ///< warps that execute the region
    std::uint64_t laneWork = 0;       ///< sum of lane work
    std::uint64_t steps = 0;          ///< serialized warp steps
};

/// A region in which lane i does work[i] units under branch key key[i]: a
/// warp executes each distinct key once, as long as the longest lane with
/// that key (a branch: work 1 per lane; a loop: work = trip count). Lanes
/// with no work are idle.
SimtStats simtStats(std::span<const std::uint32_t> order, std::span<const std::uint64_t> key,
                    std::span<const std::uint32_t> work, std::uint32_t warpSize);

/// Shader Execution Reordering: the active lanes of `order`, in windows of
/// `window` consecutive threads, stably sorted by sortKey and packed into
/// whole warps (each window padded to a warp multiple).
std::vector<std::uint32_t> serReorder(std::span<const std::uint32_t> order, std::span<const std::uint64_t> sortKey,
                                      std::uint32_t window, std::uint32_t warpSize);

/// The components of an SER sort key, most significant first: "hit", "type",
/// "cluster" and "hint" (the low hintBits bits of the thread's hint).
struct SerKey {
    std::vector<SerComponent> components;
    std::uint32_t hintBits = 0;
    SerKey() = default;
    SerKey(const SerKeySpec& spec, std::uint32_t hintBits) : components(spec.components), hintBits(hintBits) {}
    /// Parses "hit,type,cluster,hint" (parseSerKey); throws InputError naming `where` on an unknown component.
    static SerKey parse(const std::string& spec, std::uint32_t hintBits, const std::string& where);
    std::uint64_t of(const ThreadCounters& t) const;
    std::string label() const;
};

/// Before/after statistics of SER on a pass and the predicted gain, net of
/// `reorderCost` lane-steps per reordered thread.
struct SerReport {
    std::string key;
    SimtStats branchBefore, branchAfter;   ///< the branch region (branch key, work 1)
    SimtStats loopBefore, loopAfter;       ///< the loop region (trips)
    /// The rays' traversal in dispatch order, work = the particles' boxes a
    /// lane's rays cross (segment boxes): a warp lasts as long as its
    /// longest lane's traversal.
    SimtStats traversalBefore;
    /// The same with work = the BVH nodes a lane's rays visit (the
    /// traversal model's): on a GPU that traverses in software a warp loops
    /// until its longest lane's traversal ends.
    SimtStats nodesBefore;
    /// In dispatch order, work = a lane's gathers (reads at a drawn index,
    /// each waiting for the last): a warp waits for its longest chain.
    SimtStats gathersBefore;
    /// In dispatch order, work = 1 on a lane whose pixel hit a particle: its
    /// warps are those that run the pass's per-surface work at all (a warp
    /// of one hit lane costs nearly what a full one does).
    SimtStats hitsBefore;
    double distinctSortKeysBefore = 0, distinctSortKeysAfter = 0;  ///< per warp
    double reorderSteps = 0;               ///< cost of the reorder in warp steps
    double predictedSpeedup = 1.0;         ///< steps before / (steps after + reorder)
};

/// The SIMT statistics of a pass's threads (branch region on the branch key,
/// loop region on trips), cut into warps as the pass is launched
/// (passInfo(pass).launch), before and after SER with `key` in windows of `window`.
SerReport serReport(const PassCounters& pass, const WarpLayout& layout, const SerKey& key, std::uint32_t window,
                    double reorderCost);

}  // namespace accretion
