// Warp efficiency and SER on hand-built key patterns: the expected figures
// are worked out by hand in each case.
#include <catch2/catch.hpp>

#include <algorithm>
#include <numeric>

#include "accretion/gpu/warp_model.h"

using namespace accretion;

namespace {

/// One 32-wide warp-row dispatch: 32 x rows threads, groups 32 x 1.
PassCounters rowPass(std::uint32_t rows) {
    PassCounters p(Pass::traceShadowRays, 32, rows);
    for (auto& t : p.threads) t.active = 1;
    return p;
}

}  // namespace

TEST_CASE("dispatch order: 8x8 groups, two warps per group, idle lanes at the edges", "[gpu][warp]") {
    const auto order = dispatchOrder(10, 9, WarpLayout{}, PassLaunch::tiles);
    // 2 x 2 groups of 64 threads.
    REQUIRE(order.size() == 4u * 64u);
    // First warp = rows 0-3 of the first group: pixel (3, 2) is lane 2*8 + 3.
    CHECK(order[19] == 2u * 10u + 3u);
    // Second group starts at x = 8: its row 0 holds (8,0), (9,0), then idle lanes.
    CHECK(order[64] == 8u);
    CHECK(order[65] == 9u);
    CHECK(order[66] == kIdleLane);
    const auto active = std::count_if(order.begin(), order.end(), [](std::uint32_t t) { return t != kIdleLane; });
    CHECK(active == 90);
}

TEST_CASE("SIMT efficiency: one key is 100%, alternating two keys 50%, SER sorts back to 100%", "[gpu][warp]") {
    const WarpLayout layout{32, 1, 32};
    PassCounters p = rowPass(8);
    const auto order = dispatchOrder(32, 8, layout, PassLaunch::tiles);
    std::vector<std::uint64_t> key(p.threads.size(), 0);
    std::vector<std::uint32_t> work(p.threads.size(), 1);

    SimtStats one = simtStats(order, key, work, 32);
    CHECK(one.efficiency == 1.0);
    CHECK(one.distinctKeysPerWarp == 1.0);
    CHECK(one.warps == 8);

    for (std::size_t i = 0; i < key.size(); ++i) key[i] = i % 2;
    SimtStats two = simtStats(order, key, work, 32);
    CHECK(two.efficiency == 0.5);            // 32 lanes of work over 2 steps of 32 lanes
    CHECK(two.activeThreadsPerStep == 16.0);
    CHECK(two.distinctKeysPerWarp == 2.0);

    // SER over the whole dispatch: 128 threads of each key fill 4 warps each.
    const auto sorted = serReorder(order, key, 256, 32);
    SimtStats after = simtStats(sorted, key, work, 32);
    CHECK(after.efficiency == 1.0);
    CHECK(after.distinctKeysPerWarp == 1.0);
    CHECK(after.warps == 8);
    // A window of 32 threads cannot regroup anything: still 50%.
    CHECK(simtStats(serReorder(order, key, 32, 32), key, work, 32).efficiency == 0.5);
    // A window of 48 threads: windows of 24 + 24 keys, each padded to two warps (24 + 24 lanes, 16 idle each).
    const auto w48 = serReorder(order, key, 48, 32);
    CHECK(w48.size() % 32 == 0);
}

TEST_CASE("SIMT efficiency of a loop runs as long as the longest lane", "[gpu][warp]") {
    const WarpLayout layout{32, 1, 32};
    PassCounters p = rowPass(1);
    const auto order = dispatchOrder(32, 1, layout, PassLaunch::tiles);
    std::vector<std::uint64_t> key(32, 0);
    std::vector<std::uint32_t> trips(32, 1);
    trips[5] = 8;  // 31 lanes x 1 + 8 = 39 units over 8 steps
    const SimtStats s = simtStats(order, key, trips, 32);
    CHECK(s.steps == 8);
    CHECK(s.efficiency == Approx(39.0 / 256.0).epsilon(1e-12));
    // Idle lanes (no trips) do not add steps: 16 lanes of 4 trips.
    std::fill(trips.begin(), trips.end(), 0);
    std::fill(trips.begin(), trips.begin() + 16, 4);
    CHECK(simtStats(order, key, trips, 32).efficiency == 0.5);
}

TEST_CASE("SER report on a pass: keys from hit and type, gain net of the reorder cost", "[gpu][warp]") {
    PassCounters p(Pass::traceShadowRays, 32, 8);
    for (std::size_t i = 0; i < p.threads.size(); ++i) {
        ThreadCounters& t = p.threads[i];
        t.active = 1;
        t.hit = (i % 4) != 0;      // every 4th lane misses
        t.type = (i % 4) == 3;     // types 0 and 1 among the hits
        t.trips = t.hit ? 4 : 0;
        t.segmentBoxes = std::uint32_t(i % 5);
        t.nodeVisits = std::uint32_t(i % 32 == 7 ? 40 + i / 32 : 3);  // one long traversal a warp
    }
    const SerKey key = SerKey::parse("hit,type", 0, "test");
    const SerReport r = serReport(p, WarpLayout{32, 1, 32}, key, 256, 0.0);
    // A warp lasts its longest lane's traversal: boxes 4 in each of 8 warps;
    // nodes 40 + w in warp w, 8 x 40 + 28 steps, whatever its other lanes visit.
    CHECK(r.traversalBefore.steps == 8 * 4);
    CHECK(r.nodesBefore.steps == 8 * 40 + 28);
    CHECK(r.nodesBefore.warps == 8);
    // Before: 3 keys per warp (miss, type 0, type 1): 32 lanes over 3 steps.
    CHECK(r.branchBefore.distinctKeysPerWarp == 3.0);
    CHECK(r.branchBefore.efficiency == Approx(1.0 / 3.0));
    // After: 64 misses, 128 type-0 and 64 type-1 threads fill whole warps.
    CHECK(r.branchAfter.efficiency == 1.0);
    CHECK(r.branchAfter.distinctKeysPerWarp == 1.0);
    // The loop: before, every warp runs 4 trips for 24 lanes (75%); after, hit warps are full and miss warps idle.
    CHECK(r.loopBefore.efficiency == 0.75);
    CHECK(r.loopAfter.efficiency == 1.0);
    // Steps: before 8 x (3 + 4) = 56; after 8 branch steps + 6 warps x 4 trips = 32.
    CHECK(r.predictedSpeedup == Approx(56.0 / 32.0));
    // A reorder cost of 1 lane-step per thread adds 256 / 32 = 8 warp steps.
    CHECK(serReport(p, WarpLayout{32, 1, 32}, key, 256, 1.0).predictedSpeedup == Approx(56.0 / 40.0));
    CHECK_THROWS_WITH(SerKey::parse("hit,colour", 0, "scene.toml:3"), Catch::Contains("unknown SER key component 'colour'"));
}

TEST_CASE("dispatch order of a one-row launch: record order, a warp of 32 consecutive threads", "[gpu][warp]") {
    const auto order = dispatchOrder(20, 2, WarpLayout{}, PassLaunch::row);
    REQUIRE(order.size() == 64u);  // 40 threads, the second warp padded
    for (std::uint32_t i = 0; i < 40; ++i) CHECK(order[i] == i);
    CHECK(std::all_of(order.begin() + 40, order.end(), [](std::uint32_t t) { return t == kIdleLane; }));
}

TEST_CASE("SER report cuts a pass into warps as it is launched: one row for shadeSplitTexels, 8x8 tiles for shadow rays",
          "[gpu][warp]") {
    // 64 texels x 2 rays, records in launch order; runs of 32 records loop 1 and 8 trips by turns.
    auto build = [](Pass pass) {
        PassCounters p(pass, 64, 2);
        for (std::size_t i = 0; i < p.threads.size(); ++i) {
            p.threads[i].active = 1;
            p.threads[i].trips = (i / 32) % 2 ? 8 : 1;
        }
        return p;
    };
    const SerKey key = SerKey::parse("hit", 0, "test");
    // One row: 4 warps, each of one run: 1 + 8 + 1 + 8 steps for 64 x 1 + 64 x 8 lane trips, 100%.
    const SerReport row = serReport(build(Pass::shadeSplitTexels), WarpLayout{}, key, 2048, 0.0);
    CHECK(row.loopBefore.warps == 4);
    CHECK(row.loopBefore.steps == 18);
    CHECK(row.loopBefore.efficiency == 1.0);
    // 8x8 tiles of a 64 x 2 grid: 8 groups of 16 live lanes (rows 0 and 1 of 8 columns), one warp each;
    // groups 0-3 loop once, 4-7 eight times: 36 steps for 576 lane trips, 50%.
    const SerReport tiles = serReport(build(Pass::traceShadowRays), WarpLayout{}, key, 2048, 0.0);
    CHECK(tiles.loopBefore.warps == 8);
    CHECK(tiles.loopBefore.steps == 36);
    CHECK(tiles.loopBefore.efficiency == 0.5);
}
