// The pass table (core/pass.h) and the pass timer. Names are checked against
// what other programs and files wrote, not against a copy of the table: the
// GPU timings and calibrations committed under bench/gpu/results name passes
// as the H100's runs wrote them, and every one must read back as a pass.
#include <catch2/catch.hpp>

#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "accretion/core/pass_timer.h"

using namespace accretion;

namespace {

std::string repoFile(const std::string& path) {
    std::ifstream in(std::string(ACCRETION_SOURCE_DIR) + "/" + path);
    REQUIRE(in.good());
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

/// The "pass" column of a committed CSV.
std::set<std::string> passColumn(const std::string& path) {
    std::istringstream in(repoFile(path));
    std::string line;
    std::getline(in, line);
    std::size_t column = 0;
    for (std::size_t start = 0, k = 0;; ++k) {
        const std::size_t comma = line.find(',', start);
        if (line.substr(start, comma - start) == "pass") column = k;
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    std::set<std::string> out;
    while (std::getline(in, line)) {
        std::size_t start = 0;
        for (std::size_t k = 0; k < column; ++k) start = line.find(',', start) + 1;
        out.insert(line.substr(start, line.find(',', start) - start));
    }
    return out;
}

}  // namespace

TEST_CASE("every pass name the GPU runs and calibrations wrote reads back as a pass, and a run's label as its run", "[core]") {
    std::set<std::string> names;
    for (const char* csv : {"bench/gpu/results/fit_timings.csv", "bench/gpu/results/sweep_timings.csv",
                            "bench/gpu/results/sweep_counters.csv", "bench/gpu/results/layouts_timings.csv"})
        for (const std::string& n : passColumn(csv)) names.insert(n);
    const nlohmann::json fit = nlohmann::json::parse(repoFile("bench/gpu/results/fit/coefficients_h100.json"));
    for (const auto& item : fit["per_pass_ns"].items()) names.insert(item.key());
    // What those runs timed and counted: the frame's GPU passes (the twin
    // times a pass's runs together, so no file holds a run's label).
    for (const char* expected : {"buildClusters", "traceGBuffer", "generateCandidates", "temporalResampling", "spatialResampling",
                                 "traceShadowRays", "upsampleLighting", "composeImage"})
        CHECK(names.count(expected) == 1);
    for (const std::string& n : names) {
        INFO(n);
        const std::optional<PassRun> run = parsePassRun(n);
        REQUIRE(run.has_value());
        CHECK(run->label() == n);  // written back as read
    }
    CHECK(parsePassRun("spatialResampling[2]") == PassRun{Pass::spatialResampling, 2});
    CHECK(parsePassRun("spatialResampling[12]") == PassRun{Pass::spatialResampling, 12});
    CHECK(parsePass("traceShadowRays") == Pass::traceShadowRays);
}

TEST_CASE("parsePass refuses every text that is not a pass or a run's label", "[core]") {
    for (const char* bad : {"", "traceShadowRay", "TraceShadowRays", "traceShadowRays ", "spatialResampling[]",
                            "spatialResampling[0]", "spatialResampling[1]", "spatialResampling[01]", "spatialResampling[+2]",
                            "spatialResampling[2", "spatialResampling[x]", "spatialResampling[2]x",
                            "spatialResampling[99999999999]", "buildBlas", "[2]"})
        CHECK_FALSE(parsePass(bad).has_value());
}

TEST_CASE("the pass table: unique names, nesting one level deep, cost proxies that price alike", "[core]") {
    std::set<std::string_view> seen;
    for (const PassInfo& p : kPasses) {
        INFO(p.name);
        CHECK(seen.insert(p.name).second);
        CHECK(parsePass(p.name) == p.pass);
        // A proxy has coefficients of its own and the same kind of threads.
        CHECK(passInfo(p.costProxy).costProxy == p.costProxy);
        CHECK(passInfo(p.costProxy).grid == (p.grid == PassGrid::entries ? PassGrid::pixels : p.grid));
        // Host work has no GPU counterpart to nest in the lighting pass.
        if (isNested(p.pass)) CHECK(p.grid != PassGrid::host);
    }
}

TEST_CASE("PassTimer counts each closed scope of a pass, and lists the passes that ran in table order", "[core]") {
    PassTimer t;
    CHECK_FALSE(t.ran(Pass::traceGBuffer));
    { auto s = t.scope(Pass::composeImage); }
    {
        auto s = t.scope(Pass::traceGBuffer);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    { auto s = t.scope(Pass::traceGBuffer); }
    CHECK(t.runs(Pass::traceGBuffer) == 2);
    CHECK(t.runs(Pass::composeImage) == 1);
    CHECK(t.seconds(Pass::traceGBuffer) >= 0.002);  // a steady clock: the sleep is inside the scope
    CHECK_FALSE(t.ran(Pass::estimateLighting));
    CHECK(t.seconds(Pass::estimateLighting) == 0.0);
    const auto all = t.all();
    REQUIRE(all.size() == 2);
    CHECK(all[0].first == Pass::traceGBuffer);
    CHECK(all[1].first == Pass::composeImage);
}
