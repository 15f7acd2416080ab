// The GPU model as a user runs it: accretion cost and calibrate, and the
// counters' effect on rendering (none), as real processes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/student_t.h"
#include "accretion/gpu/cost_model.h"
#include "support/cli.h"
#include "support/statistics.h"

using namespace accretion;
using namespace accretion::test;

namespace {


std::string slurp(const std::filesystem::path& file) {
    REQUIRE(std::filesystem::exists(file));
    return accretion::test::readFile(file);
}

std::vector<float> readChannels(const std::filesystem::path& file, const std::vector<std::string>& names) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const OIIO::ImageSpec spec = in->spec();
    std::vector<float> all(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()));
    std::vector<float> out;
    for (const std::string& n : names) {
        const int c = spec.channelindex(n);
        REQUIRE(c >= 0);
        for (std::size_t px = 0; px < std::size_t(spec.width) * spec.height; ++px) out.push_back(all[px * spec.nchannels + c]);
    }
    return out;
}

const std::string kRestirDisc = " -D render.estimator=\\\"restir\\\" -D geometry.alpha=\\\"disc\\\" --frames 3 --history 3 ";

}  // namespace

TEST_CASE("accretion cost writes every counter, SER, any-hit/OMM and BLAS memory, and 4-state keeps the image", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("gpu_cost");
    std::string out;
    const std::string cmd = kBin + " cost " + tinyScene() + kRestirDisc + "--overhead 0 -q -o " + (dir / "c.json").string();
    INFO(cmd);
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    const nlohmann::json j = nlohmann::json::parse(slurp(dir / "c.json"));
    for (const char* key : {"passes", "blas_memory", "omm", "layouts", "ser_sweep", "any_hit_omm", "coefficients"})
        CHECK(j.contains(key));
    std::set<std::string> passes;
    for (const auto& p : j["passes"]) {
        passes.insert(p["pass"].get<std::string>());
        for (const char* key : {"simt_efficiency", "ser", "any_hit", "blas_entries", "bytes_read", "predicted_ms", "ray_model"})
            CHECK(p.contains(key));
        // Any-hits happen on rays only; every ray enters at most all clusters.
        if (p["rays"].get<double>() == 0) CHECK(p["any_hit"].get<double>() == 0);
    }
    for (const char* pass : {"buildClusters", "traceGBuffer", "generateCandidates", "temporalResampling", "spatialResampling",
                             "traceShadowRays", "composeImage"})
        CHECK(passes.count(pass));
    // OMM: 4-state leaves the image as alpha testing made it and any-hits fall with the level; 2-state has none.
    double previous = 1e30;
    for (const auto& v : j["any_hit_omm"]) {
        if (v["variant"] == "alpha") {
            previous = v["any_hits_per_shadow_ray"].get<double>() + v["any_hits_per_primary_ray"].get<double>();
            CHECK(previous > 0.0);
            continue;
        }
        if (v["states"] == 4) {
            CHECK(v["image_identical"].get<bool>());
            const double n = v["any_hits_per_shadow_ray"].get<double>() + v["any_hits_per_primary_ray"].get<double>();
            CHECK(n < previous);
            previous = n;
        } else {
            CHECK(v["any_hits_per_shadow_ray"].get<double>() == 0.0);
            CHECK_FALSE(v["image_identical"].get<bool>());
            CHECK(v["image_MAPE_vs_alpha"].get<double>() > 0.0);
            CHECK(v["Le_MAPE_vs_alpha"].get<double>() > 0.0);
            CHECK(v["pixels_changed_fraction"].get<double>() > 0.0);
        }
    }
    // Pooled BLAS memory wastes less than one allocation per BLAS at every cluster size.
    REQUIRE(j["blas_memory_by_cluster_size"].size() == 3);
    for (const auto& m : j["blas_memory_by_cluster_size"])
        CHECK(m["pooled_bytes"].get<double>() < m["per_blas_allocation_bytes"].get<double>());
    CHECK(std::filesystem::exists(dir / "c.csv"));
    CHECK(std::filesystem::exists(dir / "c.heatmaps.exr"));
    CHECK(std::filesystem::exists(dir / "c.gpu.rays.png"));
}

TEST_CASE("counters are identical for 1 and 2 threads", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("gpu_threads");
    std::string out;
    for (int t : {1, 2}) {
        const std::string cmd = kBin + " cost " + tinyScene() + kRestirDisc + "--overhead 0 --omm-levels \"\" --cluster-sizes \"\" -q --threads " +
                                std::to_string(t) + " -o " + (dir / ("t" + std::to_string(t) + ".json")).string();
        REQUIRE(runCommand(cmd, out) == 0);
    }
    CHECK(slurp(dir / "t1.csv") == slurp(dir / "t2.csv"));
    const std::vector<std::string> maps{"gpu.rays", "gpu.blas_entries", "gpu.any_hits", "gpu.trips", "gpu.bytes"};
    CHECK(readChannels(dir / "t1.heatmaps.exr", maps) == readChannels(dir / "t2.heatmaps.exr", maps));
    auto passes = [&](const std::string& f) { return nlohmann::json::parse(slurp(dir / f))["passes"].dump(); };
    CHECK(passes("t1.json") == passes("t2.json"));
}

TEST_CASE("counters on and off render the same image", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("gpu_onoff");
    std::string out;
    for (const char* on : {"false", "true"}) {
        const std::string cmd = kBin + " render " + tinyScene() +
                                " --quiet -D render.estimator=\\\"restir\\\" -D geometry.alpha=\\\"disc\\\" -D gpu.omm=\\\"4state\\\" "
                                "-D render.frames=3 -D gpu.counters=" + on + " -o " + (dir / (std::string(on) + ".{frame}.exr")).string();
        REQUIRE(runCommand(cmd, out) == 0);
    }
    const std::vector<std::string> ch{"R", "G", "B", "Lr.R", "Lr.G", "Lr.B", "restir.W", "restir.M"};
    for (const char* f : {".0000.exr", ".0002.exr"})
        CHECK(readChannels(dir / (std::string("false") + f), ch) == readChannels(dir / (std::string("true") + f), ch));
    const auto stats = nlohmann::json::parse(slurp(dir / "true.stats.json"));
    CHECK(stats["frames"][2].contains("gpu"));
    CHECK(std::filesystem::exists(dir / "true.0002.gpu.any_hits.png"));
}

TEST_CASE("calibrate recovers the coefficients that made the timings of real cost counters", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("gpu_calibrate");
    std::string out;
    // Three configurations: restir with disc alpha, power with opaque quads, exact.
    const std::vector<std::pair<std::string, std::string>> configs = {
        {"restir_disc", kRestirDisc},
        {"power", " -D render.estimator=\\\"power\\\" -D render.samples=4 "},
        {"restir_scale", " -D render.estimator=\\\"restir\\\" -D restir.resolution_scale=0.5 -D restir.basic_visibility=true "
                         "-D restir.visibility_reuse=true --frames 2 "}};
    std::vector<std::string> csvs;
    for (const auto& [name, flags] : configs) {
        const auto file = dir / (name + ".json");
        REQUIRE(runCommand(kBin + " cost " + tinyScene() + flags + "--overhead 0 --omm-levels \"\" --cluster-sizes \"\" -q --config " +
                               name + " -o " + file.string(), out) == 0);
        csvs.push_back((dir / (name + ".csv")).string());
    }
    // Timings from known coefficients (what a GPU profile would give).
    CostCoefficients truth;
    truth.ns = {0.05, 0.9, 0.6, 0.25, 1.5, 0.003};
    std::string timings = "config,pass,ms\n";
    for (const std::string& csv : csvs)
        for (const CostRow& r : readCounterCsv(csv))
            timings += r.config + "," + r.pass.label() + "," + std::to_string(truth.predictMs(r.features)) + "\n";
    {
        std::ofstream(dir / "timings.csv") << timings;
    }
    std::string cmd = kBin + " calibrate";
    for (const std::string& c : csvs) cmd += " " + c;
    cmd += " " + (dir / "timings.csv").string() + " -o " + (dir / "coef.json").string();
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    const CostCoefficients fitted = CostCoefficients::load((dir / "coef.json").string());
    // std::to_string keeps 6 decimals of ms: the fit is exact to that rounding.
    for (std::size_t k = 0; k < truth.ns.size(); ++k) {
        INFO(kCostFeatures[k]);
        CHECK(fitted.ns[k] == Approx(truth.ns[k]).epsilon(0.02));
    }
    // The cost command reads the fitted file.
    REQUIRE(runCommand(kBin + " cost " + tinyScene() + " --overhead 0 --omm-levels \"\" --cluster-sizes \"\" -q -D gpu.coefficients=\\\"" +
                           (dir / "coef.json").string() + "\\\" -o " + (dir / "again.json").string(), out) == 0);
    CHECK(nlohmann::json::parse(slurp(dir / "again.json"))["coefficients"]["source"] == (dir / "coef.json").string());

    // The same timings as Nsight and spreadsheets export them: a byte-order
    // mark, every cell quoted, CRLF line ends, a quoted comma in a config name
    // that is not used: the same fit, number for number.
    {
        std::string quoted = "\xEF\xBB\xBF\"config\",\"pass\",\"ms\"\r\n";
        std::istringstream rows(timings.substr(timings.find('\n') + 1));
        for (std::string line; std::getline(rows, line);) {
            std::string q = "\"";
            for (const char c : line) q += c == ',' ? std::string("\",\"") : std::string(1, c);
            quoted += q + "\"\r\n";
        }
        std::ofstream(dir / "nsight.csv") << quoted;
    }
    std::string nsight = kBin + " calibrate";
    for (const std::string& c : csvs) nsight += " " + c;
    REQUIRE(runCommand(nsight + " " + (dir / "nsight.csv").string() + " -o " + (dir / "coef_nsight.json").string(), out) == 0);
    CHECK(CostCoefficients::load((dir / "coef_nsight.json").string()).ns == fitted.ns);
    std::ofstream(dir / "bad3.csv") << "config,pass,ms\n\"restir_disc,traceGBuffer,1.0\n";
    CHECK(runCommand(kBin + " calibrate " + csvs[0] + " " + (dir / "bad3.csv").string() + " -o " + (dir / "x.json").string(), out) == 1);
    CHECK_THAT(out, Contains("bad3.csv:2: a quoted cell is not closed"));

    // Bad input: a name that is no pass (a pass renamed on one side), a
    // timing row without counters, a malformed number.
    std::ofstream(dir / "bad0.csv") << "config,pass,ms\npower,traceShadowRay,1.0\n";
    CHECK(runCommand(kBin + " calibrate " + csvs[0] + " " + (dir / "bad0.csv").string() + " -o " + (dir / "x.json").string(), out) == 1);
    CHECK_THAT(out, Contains("bad0.csv:2: pass 'traceShadowRay' is not a pass (passes: loadParticles,"));
    std::ofstream(dir / "bad1.csv") << "config,pass,ms\npower,presampleRegirGrid,1.0\n";
    CHECK(runCommand(kBin + " calibrate " + csvs[0] + " " + (dir / "bad1.csv").string() + " -o " + (dir / "x.json").string(), out) == 1);
    CHECK_THAT(out, Contains("no counters for config 'power' pass 'presampleRegirGrid'"));
    std::ofstream(dir / "bad2.csv") << "config,pass,ms\nrestir_disc,traceGBuffer,fast\n";
    CHECK(runCommand(kBin + " calibrate " + csvs[0] + " " + (dir / "bad2.csv").string() + " -o " + (dir / "x.json").string(), out) == 1);
    CHECK_THAT(out, Contains("bad2.csv:2: ms: 'fast' is not a finite non-negative number"));
    CHECK_FALSE(std::filesystem::exists(dir / "x.json"));
}

TEST_CASE("cost counts the launches of the builds: one per BLAS rebuilt, refitted or partly rebuilt", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("cost_launches");
    std::string out;
    // Moving particles (a static scene builds once); restir, so that cost
    // renders frame 0 before the measured frame 1.
    std::map<std::string, std::map<std::string, double>> build;  // policy -> column -> value of buildClusters
    for (const std::string policy : {"rebuild", "refit", "partial"}) {
        const std::string run = kBin + " cost " + tinyScene() + " --quiet --frames 1 --history 1 --overhead 0 --cluster-sizes \"\" " +
                                "--omm-levels \"\" -D render.estimator=\\\"restir\\\" -D particles.gm=20 -D particles.time_step=0.02 -D geometry.build=\\\"" + policy + "\\\" -o " + (dir / (policy + ".json")).string();
        INFO(run);
        REQUIRE(runCommand(run, out) == 0);
        std::ifstream csv(dir / (policy + ".csv"));
        std::string header, line;
        REQUIRE(std::getline(csv, header));
        std::vector<std::string> names;
        for (std::stringstream ss(header); std::getline(ss, line, ',');) names.push_back(line);
        while (std::getline(csv, line)) {
            std::vector<std::string> cells;
            for (std::stringstream ss(line); std::getline(ss, header, ',');) cells.push_back(header);
            REQUIRE(cells.size() == names.size());
            if (cells[1] != "buildClusters") continue;
            for (std::size_t k = 2; k < cells.size(); ++k) build[policy][names[k]] = std::stod(cells[k]);
        }
    }
    const double clusters = build["rebuild"]["threads"];
    REQUIRE(clusters > 2);
    // Every BLAS updated is a launch, and so is the TLAS over the clusters, rebuilt every frame.
    CHECK(build["rebuild"]["build_launches"] == clusters + 1);
    CHECK(build["rebuild"]["refit_launches"] == 0);
    CHECK(build["refit"]["build_launches"] == 1);  // frame 1 refits what frame 0 built
    CHECK(build["refit"]["refit_launches"] == clusters);
    CHECK(build["partial"]["build_launches"] == std::ceil(0.7 * clusters) + 1);  // geometry.rebuild_fraction
    CHECK(build["partial"]["refit_launches"] == 0);
    // Elements: a rebuild builds all it updates; a refit builds only the TLAS's instances.
    CHECK(build["rebuild"]["build_primitives"] == build["rebuild"]["accel_elements"]);
    CHECK(build["refit"]["build_primitives"] == clusters);
    CHECK(build["refit"]["accel_elements"] == build["rebuild"]["accel_elements"]);
    for (const auto& [policy, columns] : build) CHECK(columns.at("dispatches") == 1);
    CHECK(build["refit"]["sphere_refits"] == 0);  // triangles
}

TEST_CASE("cost counts the refits of built-in spheres, and a candidate's gathers: its light, and its alias entry with power", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("cost_gathers");
    std::string out;
    std::map<std::string, nlohmann::json> passes;  // run -> pass -> its JSON
    const std::string common = kBin + " cost " + tinyScene() + " --quiet --frames 1 --history 1 --overhead 0 --cluster-sizes \"\" " +
                               "--omm-levels \"\" -D render.estimator=\\\"restir\\\" -D render.candidates=8 -D particles.gm=20 -D particles.time_step=0.02 ";
    const std::map<std::string, std::string> runs = {
        {"uniform", "-D render.source=\\\"uniform\\\""},
        {"power", "-D render.source=\\\"power\\\""},
        {"spheres", "-D geometry.primitive=\\\"sphere\\\" -D geometry.build=\\\"refit\\\""}};
    for (const auto& [name, args] : runs) {
        const std::string run = common + args + " -o " + (dir / (name + ".json")).string();
        INFO(run);
        REQUIRE(runCommand(run, out) == 0);
        const nlohmann::json j = nlohmann::json::parse(slurp(dir / (name + ".json")));
        for (const auto& p : j["passes"]) passes[name][p["pass"].get<std::string>()] = p;
    }
    // Every BLAS of spheres is refitted in frame 1, and counted.
    const nlohmann::json& b = passes["spheres"]["buildClusters"];
    CHECK(b["sphere_refits"].get<double>() == b["threads"].get<double>());
    CHECK(b["sphere_refits"].get<double>() > 0.0);
    // Per candidate of a hit pixel: its light's record, and with power its alias entry.
    const nlohmann::json& u = passes["uniform"]["generateCandidates"];
    const nlohmann::json& w = passes["power"]["generateCandidates"];
    REQUIRE(u["hit_threads"].get<double>() > 10.0);
    CHECK(u["gathers"].get<double>() == 8.0 * u["hit_threads"].get<double>());
    CHECK(w["gathers"].get<double>() == 16.0 * w["hit_threads"].get<double>());
    // A shadow ray reads its light at random, and crosses particles' boxes.
    const nlohmann::json& s = passes["uniform"]["traceShadowRays"];
    CHECK(s["gathers"].get<double>() >= s["rays"].get<double>());
    CHECK(s["segment_boxes"].get<double>() > 0.0);
    // A warp runs as long as its longest lane's traversal: between the mean
    // lane's (all 32 alike) and the sum of its lanes (one lane does it all).
    CHECK(s["warp_segment_boxes"].get<double>() >= s["segment_boxes"].get<double>() / 32.0);
    CHECK(s["warp_segment_boxes"].get<double>() <= s["segment_boxes"].get<double>());
    CHECK(passes["uniform"]["generateCandidates"]["warp_segment_boxes"].get<double>() == 0.0);  // no rays
    // Uniform candidates: every hit lane reads 8 lights, so a warp with a
    // hit lane waits for 8 gathers, and only such warps wait at all.
    CHECK(u["warp_gathers"].get<double>() == 8.0 * u["hit_warps"].get<double>());
    CHECK(w["warp_gathers"].get<double>() == 16.0 * w["hit_warps"].get<double>());
    // A warp holds at most 32 hit lanes, and at least one.
    CHECK(u["hit_warps"].get<double>() >= u["hit_threads"].get<double>() / 32.0);
    CHECK(u["hit_warps"].get<double>() <= u["hit_threads"].get<double>());
    CHECK(u["hit_warps"].get<double>() < u["hit_threads"].get<double>());  // the disk covers neighbouring pixels
    CHECK(u["footprint_bytes"].get<double>() == 0.0);
}

TEST_CASE("cost counts upsampling's lighting grid once, whatever the pixels that share its texels", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("cost_footprint");
    std::string out;
    std::map<std::string, nlohmann::json> up;
    for (const std::string scale : {"0.5", "0.75"}) {
        const std::string run = kBin + " cost " + tinyScene() + " --quiet --frames 1 --history 1 --overhead 0 --cluster-sizes \"\" " +
                                "--omm-levels \"\" -D render.estimator=\\\"restir\\\" -D camera.width=64 -D camera.height=36 " +
                                "-D restir.resolution_scale=" + scale + " -o " + (dir / (scale + ".json")).string();
        INFO(run);
        REQUIRE(runCommand(run, out) == 0);
        const nlohmann::json j = nlohmann::json::parse(slurp(dir / (scale + ".json")));
        for (const auto& p : j["passes"])
            if (p["pass"] == "upsampleLighting") up[scale] = p;
    }
    REQUIRE(up.size() == 2);
    // The lighting grid is 32 x 18 texels at 0.5 and 48 x 27 at 0.75 (64 x
    // 36 scaled): each of its bytes counted once, so the footprints are in
    // the ratio of the grids' texels, whatever a texel's bytes; the threads
    // ask the same bytes at both scales (four texels a hit pixel), more than
    // the footprint at both.
    const double small = up["0.5"]["footprint_bytes"].get<double>(), large = up["0.75"]["footprint_bytes"].get<double>();
    REQUIRE(small > 0.0);
    CHECK(large / small == Approx((48.0 * 27.0) / (32.0 * 18.0)).epsilon(1e-12));
    CHECK(up["0.5"]["bytes_read"] == up["0.75"]["bytes_read"]);
    CHECK(large < up["0.75"]["bytes_read"].get<double>());
}

TEST_CASE("cost counts the rays that found nothing, and a traced pass's working set holds the TLAS", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("cost_misses");
    std::string out;
    const std::string run = kBin + " cost " + tinyScene() + " --quiet --frames 1 --history 1 --overhead 0 --cluster-sizes \"\" " +
                            "--omm-levels \"\" -D render.estimator=\\\"restir\\\" -D geometry.layout=\\\"instances\\\" -o " +
                            (dir / "c.json").string();
    INFO(run);
    REQUIRE(runCommand(run, out) == 0);
    const nlohmann::json j = nlohmann::json::parse(slurp(dir / "c.json"));
    std::map<std::string, nlohmann::json> pass;
    for (const auto& p : j["passes"]) pass[p["pass"].get<std::string>()] = p;
    // A primary ray misses on exactly the pixels whose thread found no hit
    // (hit_threads is counted apart, by the shading that follows a hit).
    const nlohmann::json& g = pass.at("traceGBuffer");
    CHECK(g["misses"].get<double>() == g["threads"].get<double>() - g["hit_threads"].get<double>());
    CHECK(g["misses"].get<double>() > 0.0);
    // Shadow rays in a cloud of particles: some are blocked, some not.
    const nlohmann::json& s = pass.at("traceShadowRays");
    CHECK(s["misses"].get<double>() > 0.0);
    CHECK(s["misses"].get<double>() < s["rays"].get<double>());
    // Passes without rays have none.
    CHECK(pass.at("temporalResampling")["misses"].get<double>() == 0.0);
    // One instance per particle: the traced passes read the TLAS beside one
    // BLAS of two triangles. A TLAS instance's bytes as OptiX built them on
    // the H100 (bench/gpu/results/layouts.csv: tlas_bytes / instances of the
    // instances layout, 10K to 1M particles, rebuilt and refitted).
    double lo = 1e30, hi = 0.0;
    {
        std::istringstream csv(slurp(std::filesystem::path(ACCRETION_SOURCE_DIR) / "bench/gpu/results/layouts.csv"));
        std::string line, cell;
        std::getline(csv, line);
        std::vector<std::string> names;
        for (std::stringstream ss(line); std::getline(ss, cell, ',');) names.push_back(cell);
        const auto column = [&](const char* n) { return std::size_t(std::find(names.begin(), names.end(), n) - names.begin()); };
        const std::size_t layout = column("layout"), tlas = column("tlas_bytes"), instances = column("instances");
        while (std::getline(csv, line)) {
            std::vector<std::string> cells;
            for (std::stringstream ss(line); std::getline(ss, cell, ',');) cells.push_back(cell);
            if (cells.at(layout) != "instances") continue;
            const double perInstance = std::stod(cells.at(tlas)) / std::stod(cells.at(instances));
            lo = std::min(lo, perInstance);
            hi = std::max(hi, perInstance);
        }
    }
    REQUIRE(hi > 0.0);
    const double particles = pass.at("buildClusters")["threads"].get<double>();
    REQUIRE(particles > 100);
    CHECK(g["working_set_bytes"].get<double>() >= lo * particles);
    CHECK(g["working_set_bytes"].get<double>() < hi * particles + 4096.0);
}

TEST_CASE("tune: a Pareto front of predicted GPU ms against error, the best unbiased one under the budget, cached",
          "[cli][gpu][tune][long]") {
    const auto dir = accretion::test::scratchDir("tune");
    // An M cap of 8: the steady state's history is 8 frames (the least it
    // may be), so each bias run renders 9 frames, not 21 (minutes under ASan).
    // Under the sanitizers (a seed divisor) the same configurations on a
    // frame half as wide and high, measured on one crop instead of four, of
    // half the particles: every path of tune runs, on a sixteenth of the
    // pixels (the whole run took 174 s of CI under ASan; with 800 particles
    // and particle_split's ten, 89 s alone, with 400 59 s).
    const bool whole = fullStatisticalPower();
    const std::uint32_t width = whole ? 96 : 48, height = whole ? 64 : 32, cropW = width / 3, cropH = height * 3 / 8, strata = whole ? 2 : 1;
    const std::size_t crops = strata * strata;
    const std::string frame = whole ? std::string() : " -D camera.width=48 -D camera.height=32 -D particles.count=400";
    const std::string base = kBin + " tune " + tinyScene() + frame + " -D restir.m_cap=8 --error-crops " + std::to_string(strata) + "x" +
                             std::to_string(strata) + " --crop-size " + std::to_string(cropW) + "x" + std::to_string(cropH) + " --crop-margin " +
                             std::to_string(cropH / 3) + " --seeds 3 --cache " + (dir / "cache").string() + " -o " + (dir / "t").string() +
                             " --budget-ms 50";
    const std::string cmd = base + " --max-seeds 3";
    std::string out;
    REQUIRE(runCommand(cmd, out) == 0);
    INFO(out);
    const nlohmann::json j = nlohmann::json::parse(slurp(dir / "t.json"));
    // Every measured point: the front is exactly the set no other point beats on both axes.
    const nlohmann::json& rows = j.at("lighting");
    const std::size_t quick = 34 + 8 + 2 + 12;  // restir, particle_restir, voxel_cache, particle_split
    REQUIRE(rows.size() == quick);
    for (const auto& p : rows) {
        bool dominated = false;
        for (const auto& q : rows)
            dominated |= q["gpu_ms"].get<double>() <= p["gpu_ms"].get<double>() && q["rel_mse"].get<double>() < p["rel_mse"].get<double>() &&
                         (q["gpu_ms"].get<double>() < p["gpu_ms"].get<double>() || q["rel_mse"].get<double>() < p["rel_mse"].get<double>());
        CHECK(p["front"].get<bool>() == !dominated);
    }
    // The recommendation: under the budget, never biased; one whose seeds
    // could see a 1% bias before one they could not; the lowest error of its class.
    const nlohmann::json& r = j.at("recommended");
    REQUIRE(r.is_object());
    CHECK(r["gpu_ms"].get<double>() <= 50.0);
    CHECK_FALSE(r["biased"].get<bool>());
    bool anyUnbiased = false;
    for (const auto& p : rows) {
        const std::string v = p["bias_verdict"];
        anyUnbiased |= v == "unbiased" && p["gpu_ms"].get<double>() <= 50.0;
        // A verdict of unbiased is one a 1% energy bias would have broken 4 times in 5.
        if (v == "unbiased") CHECK(p["detectable_bias_pct"].get<double>() <= 1.0);
        if (v == "unknown") CHECK(p["detectable_bias_pct"].get<double>() > 1.0);
        CHECK(p["biased"].get<bool>() == (v == "biased"));
    }
    CHECK(r["bias_verdict"] == (anyUnbiased ? "unbiased" : "unknown"));
    // tune searches across designs: each design's best under the budget, the recommendation one of them.
    const nlohmann::json& designs = j.at("best_per_design");
    REQUIRE(designs.contains("restir"));
    REQUIRE(designs.contains("particle_restir"));
    // The voxel cache and particle_split are biased by design: each has a best only where a point of it was under the budget
    // and no test detected its bias.
    for (const auto& [design, prefix] : {std::pair{"voxel_cache", "voxels"}, std::pair{"particle_split", "split"}}) {
        bool eligible = false;
        for (const auto& p : rows)
            eligible |= p["lighting"].get<std::string>().starts_with(prefix) && !p["biased"].get<bool>() && p["gpu_ms"].get<double>() <= 50.0;
        INFO(design);
        CHECK(designs.contains(design) == eligible);
    }
    CHECK(designs.at(r["design"].get<std::string>())["lighting"] == r["lighting"]);
    for (const auto& [design, best] : designs.items()) {
        CHECK(best["rel_mse"].get<double>() >= r["rel_mse"].get<double>());
        CHECK(best["error_vs_recommended"].get<double>() == Approx(best["rel_mse"].get<double>() / r["rel_mse"].get<double>()));
    }
    // Reuse per configuration, at the steady state it was measured at: no
    // spatial pass without neighbours; every offer of the passes that ran counted.
    // Each configuration after its own steady state, the frame after the
    // longest: restir's and particle_restir's M cap of 8 frames; the voxel
    // cache's running mean to voxel.history = 16; particle_split's texel
    // average until its first frame weighs under 1% (0.75^17 < 0.01 <=
    // 0.75^16, 0.9^44 < 0.01 <= 0.9^43; from a running mean at h = 0.95,
    // 1/20 after 19 frames, then 0.05 x 0.95^32 < 0.01 <= 0.05 x 0.95^31).
    const auto historyOf = [](const std::string& spec) {
        return spec.find("particle_split.history=0.95:") != std::string::npos   ? 51
               : spec.find("particle_split.history=0.9:") != std::string::npos  ? 44
               : spec.find("particle_split.history=0.75:") != std::string::npos ? 17
               : spec.starts_with("voxel_cache")                                 ? 16
                                                                                 : 8;
    };
    const nlohmann::json longer = {{"split near=8 far=4 C=8 h=0.9 1x1", 44},  {"split near=16 far=8 C=8 h=0.9 1x1", 44},
                                   {"split near=8 far=4 C=8 h=0.75 1x1", 17}, {"split near=16 far=8 C=8 h=0.75 1x1", 17},
                                   {"split near=16 far=16 C=8 h=0.75 1x1", 17}, {"voxels tree cells=32 rays=8 camera", 16},
                                   {"voxels tree cells=64 rays=8 camera", 16},
                                   {"split near=8 far=4 C=8 h=0.95 1x1 mean far-only", 51},
                                   {"split near=8 far=4 C=8 h=0.95 1x1 mean far-only prior32 share64", 51},
                                   {"split near=8 far=4 C=8 h=0.95 1x1 mean far-only prior32 share256", 51},
                                   {"split near=8 far=4 C=4 h=0.95 1x1 anti mean far-only prior32 share256", 51},
                                   {"split near=16 far=8 C=8 h=0.95 1x1 mean far-only prior32 share256", 51},
                                   {"split near=8 far=4 C=8 h=0.95 1x1 mean far-only prior32 share256 handoff", 51},
                                   {"split near=16 far=8 C=8 h=0.95 1x1 mean far-only prior32 share256 handoff", 51}};
    CHECK(j["frame"] == 51);
    CHECK(j["history_frames"] == 8);
    CHECK(j["longer_histories"] == longer);
    std::size_t biasRuns = 0;  // and each bias run rendered its own history before frame 51
    for (const auto& e : std::filesystem::directory_iterator(dir / "cache"))
        if (e.path().string().ends_with(".bias.json")) {
            const nlohmann::json run = nlohmann::json::parse(slurp(e.path()));
            const std::string spec = run.at("rows").at(0).at("estimator");
            INFO(spec);
            CHECK(run.at("frame") == 51);
            CHECK(run.at("rows").at(0).at("history_frames") == historyOf(spec));
            ++biasRuns;
        }
    CHECK(biasRuns == quick);
    CHECK(j["cost_history_frames"] == 2);  // the counted frame's temporal pass runs; its price does not need the M cap
    for (const auto& p : rows) {
        const std::string label = p["lighting"];
        INFO(label);
        if (label.starts_with("voxels") || label.starts_with("split")) {  // cells or texels by id, not reservoirs: no reuse passes, no offers
            CHECK_FALSE(j.at("reuse").contains(label));
            CHECK(p["temporal_kept_pct"].is_null());
            continue;
        }
        const nlohmann::json& reuse = j.at("reuse").at(label);
        CHECK(reuse.at("temporalResampling").at("offered").get<double>() > 0.0);
        const double temporal = p["temporal_kept_pct"].get<double>();
        CHECK((temporal > 0.0 && temporal <= 100.0));
        if (label.find("nb=0x") != std::string::npos) {
            CHECK(p["spatial_kept_pct"].is_null());
            CHECK_FALSE(reuse.contains("spatialResampling"));
            CHECK_FALSE(reuse.contains("resampleWorldNeighbours"));
        } else {
            const double spatial = p["spatial_kept_pct"].get<double>();
            CHECK((spatial >= 0.0 && spatial <= 100.0));
            // particle_restir's world neighbours are a pass of their own, restir's screen disc another.
            const bool particles = label.rfind("particles", 0) == 0;
            CHECK(reuse.contains(particles ? "resampleWorldNeighbours" : "spatialResampling"));
            CHECK_FALSE(reuse.contains(particles ? "spatialResampling" : "resampleWorldNeighbours"));
        }
    }
    for (const auto& p : rows)
        if (p["bias_verdict"] == r["bias_verdict"] && p["gpu_ms"].get<double>() <= 50.0)
            CHECK(p["rel_mse"].get<double>() >= r["rel_mse"].get<double>());
    // The geometry: the fastest predicted of its options (none changes the image).
    double fastest = 1e300;
    for (const auto& g : j.at("geometry")) fastest = std::min(fastest, g["frame_ms"].get<double>());
    for (const auto& g : j.at("geometry"))
        if (g["geometry"] == j["chosen_geometry"]) CHECK(g["frame_ms"].get<double>() == fastest);
    CHECK(std::filesystem::exists(dir / "t.csv"));

    // Where the time went: every measurement of the first run was run, none cached.
    const nlohmann::json firstTime = j.at("time");
    // Each configuration's bias once: --max-seeds 3 adds none (the escalation is checked below, with --max-seeds 12).
    for (const auto& p : rows) CHECK(p["seeds"] == 3);
    CHECK(firstTime["error (bias)"]["runs"] == quick);
    CHECK(firstTime["error (bias)"]["cached"] == 0);
    CHECK(firstTime["GPU time (cost)"]["runs"] == 12 + quick);
    CHECK(firstTime["references"]["runs"] == crops);  // one per crop
    // Measured where the engine runs: crops of the frame, one per stratum, at its resolution.
    REQUIRE(j.at("crops").size() == crops);
    for (std::size_t k = 0; k < crops; ++k) {
        const auto& c = j["crops"][k];
        const std::uint32_t x0 = c[0], x1 = c[1], y0 = c[2], y1 = c[3], col = k % strata, row = k / strata;
        CHECK(x1 - x0 == cropW);
        CHECK(y1 - y0 == cropH);
        CHECK(x0 >= width / strata * col);
        CHECK(x1 <= width / strata * (col + 1));
        CHECK(y0 >= height / strata * row);
        CHECK(y1 <= height / strata * (row + 1));
    }
    // A second run reads every measurement back and gives the same table.
    const std::string first = slurp(dir / "t.csv");
    std::filesystem::remove(dir / "t.csv");
    std::filesystem::remove(dir / "t.json");
    std::filesystem::remove(dir / "t.png");
    REQUIRE(runCommand(cmd, out) == 0);
    std::istringstream lines(out);
    std::size_t measurements = 0;
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("tune: [", 0) == 0) {
            ++measurements;
            CHECK_THAT(line, Contains("(cached)"));
        }
    CHECK(measurements == crops + 12 + 2 * quick);  // the crops' references, 6 layouts rebuilt and refitted, then cost and bias per lighting option
    CHECK(slurp(dir / "t.csv") == first);
    // ... and accounts for the cached measurements with what they cost when run (kept beside them, to the ms).
    const nlohmann::json again = nlohmann::json::parse(slurp(dir / "t.json")).at("time");
    for (const char* kind : {"references", "GPU time (cost)", "error (bias)"}) {
        INFO(kind);
        CHECK(again[kind]["runs"] == 0);
        CHECK(again[kind]["cached"] == firstTime[kind]["runs"]);
        CHECK(again[kind]["cached_seconds"].get<double>() == Approx(firstTime[kind]["seconds"].get<double>()).margin(1e-3 * 50));
    }

    // --errors-from: another calibration prices the same measurements
    // without a reference or a bias run. Every coefficient of the committed
    // calibration doubled (the model is linear in them, and the cache of
    // cold_work is the same): every price doubles, and each configuration's
    // error, seeds and verdict are the first run's.
    std::filesystem::copy_file(dir / "t.json", dir / "first.json");
    nlohmann::json doubled = CostCoefficients::committed().toJson();
    for (auto& [feature, ns] : doubled.at("coefficients_ns").items()) ns = 2.0 * ns.get<double>();
    for (auto& [pass, features] : doubled.at("per_pass_ns").items())
        for (auto& [feature, ns] : features.items()) ns = 2.0 * ns.get<double>();
    {
        std::ofstream(dir / "doubled.json") << doubled.dump(1);
    }
    // A command with one of its options changed: "--seeds 3" -> "--seeds 4".
    const auto with = [](std::string c, const std::string& option, const std::string& value) {
        const std::size_t at = c.find(" " + option + " ");
        const std::size_t end = c.find(' ', at + option.size() + 2);
        return c.replace(at, (end == std::string::npos ? c.size() : end) - at, " " + option + " " + value);
    };
    const std::string fromFirst = " --max-seeds 3 --errors-from " + (dir / "first.json").string();
    const std::string doubledCalibration = " -D 'gpu.coefficients=\"" + (dir / "doubled.json").string() + "\"'";
    REQUIRE(runCommand(with(base, "-o", (dir / "re").string()) + fromFirst + doubledCalibration, out) == 0);
    {
        const nlohmann::json re = nlohmann::json::parse(slurp(dir / "re.json"));
        CHECK(re.at("errors_from").at("file") == (dir / "first.json").string());
        CHECK(re.at("errors_from").at("version") == j.at("version"));
        CHECK(re.at("references") == j.at("references"));  // what its errors were measured against
        for (const char* kind : {"references", "error (bias)"}) {
            INFO(kind);
            CHECK(re.at("time").at(kind).at("runs") == 0);
            CHECK(re.at("time").at(kind).at("cached") == 0);
        }
        CHECK(re.at("time").at("GPU time (cost)").at("cached") == 12 + quick);  // the counts are the cache's: only their price is new
        std::map<std::string, nlohmann::json> was;
        for (const auto& p : rows) was[p["lighting"]] = p;
        REQUIRE(re.at("lighting").size() == quick);
        for (const auto& p : re.at("lighting")) {
            const nlohmann::json& w = was.at(p["lighting"]);
            INFO(p["lighting"]);
            CHECK(p["gpu_ms"].get<double>() == Approx(2.0 * w["gpu_ms"].get<double>()).epsilon(1e-9));
            for (const char* same : {"rel_mse", "seeds", "bias_verdict", "detectable_bias_pct", "energy_loss_pct", "temporal_kept_pct"})
                CHECK(p[same] == w[same]);
        }
        for (std::size_t g = 0; g < j.at("geometry").size(); ++g)
            CHECK(re["geometry"][g]["frame_ms"].get<double>() == Approx(2.0 * j["geometry"][g]["frame_ms"].get<double>()).epsilon(1e-9));
        // The same recommendation: every price scaled alike, under a budget scaled alike.
        REQUIRE(runCommand(with(with(base, "-o", (dir / "re100").string()), "--budget-ms", "100") + fromFirst +
                               doubledCalibration, out) == 0);
        CHECK(nlohmann::json::parse(slurp(dir / "re100.json")).at("recommended").at("lighting") == r.at("lighting"));
    }
    // ... from a run at this operating point only, naming what differs; nothing written.
    const std::string bad = with(base, "-o", (dir / "bad").string()), from = bad + " --max-seeds 3 --errors-from ";
    CHECK(runCommand(with(bad, "--seeds", "4") + fromFirst, out) == 1);
    CHECK_THAT(out, Contains("measured at another operating point: seeds 3 there, 4 here"));
    CHECK(runCommand(from + (dir / "first.json").string() + " -D particles.seed=77", out) == 1);
    CHECK_THAT(out, Contains("measured another scene: [particles]"));
    CHECK_THAT(out, Contains("'seed = 77' here"));
    CHECK(runCommand(from + (dir / "doubled.json").string(), out) == 1);
    CHECK_THAT(out, Contains("doubled.json: not the JSON of a tune run"));
    {
        nlohmann::json fewer = nlohmann::json::parse(slurp(dir / "first.json"));
        const std::string dropped = fewer.at("lighting").at(0).at("lighting");
        fewer.at("lighting").erase(0);
        std::ofstream(dir / "fewer.json") << fewer.dump();
        CHECK(runCommand(from + (dir / "fewer.json").string(), out) == 1);
        CHECK_THAT(out, Contains("fewer.json: no error measurement of '" + dropped + "'"));
    }
    CHECK_FALSE(std::filesystem::exists(dir / "bad.json"));
    // A run from before the space grew, at frame 8 (no texel history longer
    // than the M cap then): priced at its frame, the configurations that do
    // not fit before it left out and named; with --frame 51 refused.
    {
        nlohmann::json before = nlohmann::json::parse(slurp(dir / "first.json"));
        before["frame"] = 8;
        before.erase("longer_histories");
        std::ofstream(dir / "before.json") << before.dump();
        const std::string fromBefore = with(base, "-o", (dir / "at8").string()) +
                                       " --max-seeds 3 --designs particle_restir,particle_split --errors-from " + (dir / "before.json").string();
        CHECK(runCommand(fromBefore + " --frame 51", out) == 1);
        CHECK_THAT(out, Contains("before.json: measured at another operating point: frame 8 there, 51 here"));
        REQUIRE(runCommand(fromBefore, out) == 0);
        CHECK_THAT(out, Contains("left out: split near=8 far=4 C=8 h=0.9 1x1 needs 44 history frames"));
        const nlohmann::json at8 = nlohmann::json::parse(slurp(dir / "at8.json"));
        CHECK(at8.at("frame") == 8);
        CHECK(at8.at("longer_histories") == nlohmann::json::object());
        // particle_split's twelve need more than 8 frames (17 at h = 0.75, 44 at 0.9, 51 at 0.95 from a running mean, as above).
        nlohmann::json leftOut = longer;
        leftOut.erase("voxels tree cells=32 rays=8 camera");
        leftOut.erase("voxels tree cells=64 rays=8 camera");
        CHECK(at8.at("errors_from").at("left_out") == leftOut);
        std::map<std::string, nlohmann::json> was;
        for (const auto& p : rows) was[p["lighting"]] = p;
        REQUIRE(at8.at("lighting").size() == 8);  // particle_restir's, their errors the first run's
        for (const auto& p : at8.at("lighting")) {
            INFO(p["lighting"]);
            CHECK(p["lighting"].get<std::string>().starts_with("particles"));
            CHECK(p["rel_mse"] == was.at(p["lighting"])["rel_mse"]);
        }
    }

    // Where a bias of --bias-bound could hide in 3 seeds' verdict, tune runs
    // the fewest seeds that would see it when --max-seeds allows, in the
    // order the recommendation ranks the configurations (by error), until one
    // is verified unbiased; the rest keep "bias unknown" with their bound.
    // The exact references have no noise, so the bound is Student's
    // (t_crit + t_0.8) sigma / sqrt(S) with S - 1 degrees of freedom: with the
    // 3 seeds' sigma and tune's 10% spare on its variance, the seeds needed
    // follow from the 3 seeds' bound alone.
    // A bound of 5%: the best-ranked configurations (particle_restir's,
    // bounds of 7% and more with 3 seeds) need more seeds to be told.
    // Under the sanitizers particle_restir's 8 alone (--designs): the same
    // escalation, without the voxel cache's 11 seeds and particle_split's 6
    // (21 of its 23 s under ASan), at the first run's frame (51: its
    // particle_split at h = 0.95), which particle_restir alone would not move to.
    const double boundPct = 5.0;
    REQUIRE(runCommand(base + " --bias-bound 5 --max-seeds 12 -q" + (whole ? "" : " --designs particle_restir --frame 51"), out) == 0);
    const nlohmann::json k = nlohmann::json::parse(slurp(dir / "t.json"));
    std::map<std::string, nlohmann::json> first3;
    for (const auto& p : rows) first3[p["lighting"]] = p;
    const double significance = 1.0 - 0.5 * std::erfc(3.29 / std::sqrt(2.0));  // bias's default --z, one side
    auto perSigma = [&](std::uint32_t s) {
        return (studentTQuantile(significance, s - 1.0) + studentTQuantile(0.8, s - 1.0)) / std::sqrt(double(s));
    };
    // The seeds tune would measure next after a row of n seeds: n where none would do.
    auto neededAfter = [&](const nlohmann::json& row) {
        const std::uint32_t n = row["seeds"].get<std::uint32_t>();
        const double b = row["detectable_bias_pct"].get<double>();
        if (row["biased"].get<bool>() || b <= boundPct) return n;
        for (std::uint32_t s = n + 1; s <= 12; ++s)
            if (b * std::sqrt(1.1) * perSigma(s) / perSigma(n) <= boundPct) return s;
        return n;
    };
    const nlohmann::json& rk = k.at("recommended");
    REQUIRE(rk.is_object());
    std::size_t more = 0;
    for (const auto& p : k.at("lighting")) {
        const nlohmann::json& p3 = first3.at(p["lighting"]);
        const std::uint32_t seeds = p["seeds"].get<std::uint32_t>();
        INFO(p["lighting"] << ": bound " << p3["detectable_bias_pct"] << "% with 3 seeds, " << p["detectable_bias_pct"] << "% with "
                           << seeds);
        if (seeds > 3) {
            // The fewest seeds the 3 seeds' spread asked for, then more from each
            // measurement's own spread while one still would tell: the last
            // is told, or no count up to --max-seeds would tell it.
            ++more;
            CHECK(seeds >= neededAfter(p3));
            CHECK(neededAfter(p) == seeds);
        } else if (rk["bias_verdict"] == "unbiased" && p3["bias_verdict"] == "unknown" && p["gpu_ms"].get<double>() <= 50.0 &&
                   p3["rel_mse"].get<double>() < rk["rel_mse"].get<double>()) {
            // Ranked before the recommendation, left with 3 seeds and unknown: no seeds up to 12 would have told.
            CHECK(neededAfter(p3) == 3);
        }
    }
    CHECK(more > 0);
    // --anatomy: each configuration again with every light visible, against
    // a reference without visibility that tune renders once: visibility's
    // share of the error, mostly between 0 and 100% (one shadow ray a pixel
    // is noise of its own). --designs particle_restir: its 8 alone (restir's
    // anatomy at the operating point is bench/operating_point.sh's; 34 more
    // bias runs here cost CI a minute under ASan). In the Release stage only:
    // its bias runs are the ones above with every light visible, and under
    // ASan they took 9 s of a stage at CI's limit.
    if (whole) {
        REQUIRE(runCommand(cmd + " --anatomy --designs particle_restir -q", out) == 0);
        const nlohmann::json an = nlohmann::json::parse(slurp(dir / "t.json"));
        CHECK(an["unshadowed_references"].size() == crops);
        CHECK(an.at("lighting").size() == 8);
        CHECK_FALSE(an.at("best_per_design").contains("restir"));
        std::vector<double> shares;
        for (const auto& p : an.at("lighting")) shares.push_back(p["visibility_share_pct"].get<double>());
        std::sort(shares.begin(), shares.end());
        const double median = shares[shares.size() / 2];
        INFO("visibility's share of the error, median over the configurations: " << median << "%");
        CHECK((median > 0.0 && median < 100.0));
    }

    // Bad input: one clear error each, exit 1, nothing written.
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 0 -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--budget-ms"));
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 5 --error-crops 4 -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--error-crops 4: expected AxB"));
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 5 --error-crops 4x4 --crop-size 32x24 -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--crop-size 32x24: a crop must fit its stratum, 24x16"));
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 5 --space huge -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--space huge"));
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 5 --designs restir,voxels -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--designs voxels: expected restir, particle_restir, voxel_cache or particle_split"));
    CHECK(runCommand(kBin + " tune " + tinyScene() + " --budget-ms 5 --error-crops 2x2 --crop-size 32x24 --reference " +
                         (dir / "t.csv").string() + " --cache " + (dir / "bad_cache").string() + " -o " + (dir / "bad").string(), out) == 1);
    CHECK_THAT(out, Contains("--reference: 1 given, one per crop of --error-crops 2x2 (4)"));
    CHECK_FALSE(std::filesystem::exists(dir / "bad_cache"));
    CHECK_FALSE(std::filesystem::exists(dir / "bad.json"));
}

TEST_CASE("a configuration label with commas and quotes stays one CSV cell from cost to calibrate", "[cli][gpu]") {
    const auto dir = accretion::test::scratchDir("gpu_config_comma");
    std::string out;
    const std::string label = "tree, M=8 \\\"hd\\\"";  // as the shell passes it: tree, M=8 "hd"
    REQUIRE(runCommand(kBin + " cost " + tinyScene() + " -D render.estimator=\\\"restir\\\" --frames 2 --overhead 0 --omm-levels \"\" "
                           "--cluster-sizes \"\" -q --config \"" + label +
                           "\" -o " + (dir / "c.json").string(), out) == 0);
    const std::vector<CostRow> rows = readCounterCsv((dir / "c.csv").string());
    REQUIRE(rows.size() >= 3);
    for (const CostRow& r : rows) CHECK(r.config == "tree, M=8 \"hd\"");
    // calibrate joins the label as a spreadsheet quotes it.
    std::string timings = "config,pass,ms\n";
    for (const CostRow& r : rows) timings += "\"tree, M=8 \"\"hd\"\"\"," + r.pass.label() + "," + std::to_string(0.01 + r.features[0] * 1e-6) + "\n";
    std::ofstream(dir / "t.csv") << timings;
    REQUIRE(runCommand(kBin + " calibrate " + (dir / "c.csv").string() + " " + (dir / "t.csv").string() + " -o " + (dir / "k.json").string(),
                       out) == 0);
    CHECK_THAT(out, Contains("fitted on " + std::to_string(rows.size()) + " timed passes"));
}
