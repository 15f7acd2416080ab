// tune under the faults of a real run, with real processes: a stop request
// (SIGTERM) while a measurement runs, a second tune on the same cache, a
// particle file replaced under the same scene, a damaged cache entry.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/cli.h"

namespace fs = std::filesystem;
using namespace accretion::test;

namespace {

/// A shell line that waits (up to 120 s) until `file` holds `text`.
std::string waitFor(const fs::path& file, const std::string& text) {
    return "i=0; while ! grep -qF -- '" + text + "' " + file.string() + " 2>/dev/null && [ $i -lt 2400 ]; do sleep 0.05; i=$((i+1)); done\n";
}

/// `tune` started in the background, stopped with SIGTERM once its stderr
/// (`err`) shows `text`; `between` runs while it is alive. Prints
/// "status=N" and whether any process still names `cache`.
std::string stopTuneAt(const std::string& tune, const fs::path& err, const std::string& text, const fs::path& cache,
                       const std::string& between = "") {
    return tune + " > /dev/null 2> " + err.string() + " & P=$!\n" + between + waitFor(err, text) + "kill -TERM $P; wait $P; echo \"status=$?\"\n" +
           "sleep 0.2; if pgrep -f -- '" + cache.string() + "' > /dev/null; then echo orphans; else echo no-orphans; fi\n";
}

std::string run(const fs::path& dir, const std::string& name, const std::string& script) {
    std::ofstream(dir / (name + ".sh")) << script;
    std::string out;
    runCommand("sh " + (dir / (name + ".sh")).string() + " 2>&1", out);
    return out;
}

/// The cache holds no lock and no temporary a stopped writer left.
void requireTidyCache(const fs::path& cache) {
    for (const auto& e : fs::directory_iterator(cache)) {
        const std::string name = e.path().filename().string();
        INFO(name);
        CHECK(name.front() != '.');
        CHECK(name != "tune.lock");
    }
}

}  // namespace

TEST_CASE("tune stopped by SIGTERM: its measurement stops with it, the cache stays whole, the same command resumes",
          "[cli][tune][fault][signal]") {
    const fs::path dir = scratchDir("tune_sigterm");
    const fs::path cache = dir / "cache";
    // 30000 particles: the reference is split's, at enough samples that it is
    // still rendering when the signal comes (each band a fraction of a second).
    const std::string tune = kBin + " tune " + tinyScene() + " -D particles.count=30000 -D restir.m_cap=8 --error-crops 1x1 "
                             "--crop-size 32x24 --crop-margin 8 --seeds 2 --max-seeds 2 --budget-ms 50 --reference-spp 32768 --cache " +
                             cache.string() + " -o " + (dir / "t").string();
    // The signal comes once the reference's render is lighting ("accretion: frame" in its log).
    const std::string lighting = waitFor(cache / "*.ref.exr.log", "accretion: frame");
    std::string out = run(dir, "first", stopTuneAt(tune, dir / "err1", "[1/", cache, lighting));
    std::string err = readFile(dir / "err1");
    INFO(out << "\n" << err);
    CHECK_THAT(out, Contains("status=143"));
    CHECK_THAT(out, Contains("no-orphans"));  // the reference's render stopped with tune
    CHECK_THAT(err, Contains("tune: SIGTERM: stopped at reference (split 32768 spp") && Contains("the same command resumes from it"));
    requireTidyCache(cache);
    // The reference render checkpointed its samples rather than dying.
    std::size_t checkpoints = 0;
    for (const auto& e : fs::directory_iterator(cache)) checkpoints += e.path().extension() == ".checkpoint";
    CHECK(checkpoints == 1);
    CHECK_FALSE(fs::exists(dir / "t.csv"));

    // The same command again: the reference continues from its checkpoint.
    for (const auto& e : fs::directory_iterator(cache))  // the first run's logs: the wait below reads the second's
        if (e.path().extension() == ".log") fs::remove(e.path());
    out = run(dir, "second", stopTuneAt(tune, dir / "err2", "[1/", cache, lighting));
    err = readFile(dir / "err2");
    INFO(out << "\n" << err);
    CHECK_THAT(out, Contains("status=143"));
    CHECK_THAT(out, Contains("no-orphans"));
    std::string logs;
    for (const auto& e : fs::directory_iterator(cache))
        if (e.path().extension() == ".log") logs += readFile(e.path());
    CHECK_THAT(logs, Contains("accretion: resuming "));
    requireTidyCache(cache);
}

TEST_CASE("tune's cache: keyed by the particle file's content, one tune at a time, a damaged entry named and kept",
          "[cli][tune][fault]") {
    const fs::path dir = scratchDir("tune_cache_faults");
    const fs::path cache = dir / "cache";
    std::string out;
    // Two dumps of 800 particles (generator seeds 7 and 9), one scene that reads parts.bin.
    for (const char* seed : {"7", "9"})
        REQUIRE(runCommand(kBin + " particles " + tinyScene() + " -D particles.seed=" + seed + " --frames 0:1 --out " +
                               (dir / (std::string("seed") + seed)).string(), out) == 0);
    const auto dump = [&](const char* seed) { return dir / (std::string("seed") + seed) / "small_disk.0000.bin"; };
    std::string scene = readFile(tinyScene());
    scene.replace(scene.find("count = 800"), 11, "file = \"parts.bin\"");
    std::ofstream(dir / "scene.toml") << scene;
    fs::copy_file(dump("7"), dir / "parts.bin");
    const std::string tune = kBin + " tune " + (dir / "scene.toml").string() + " -D restir.m_cap=8 --error-crops 2x1 --crop-size 32x24 "
                             "--crop-margin 8 --seeds 2 --max-seeds 2 --budget-ms 50 --cache " + cache.string() + " -o " +
                             (dir / "t").string();

    // While one tune holds the cache, a second is refused, naming the first.
    const std::string second = tune + " > " + (dir / "second.txt").string() + " 2>&1; echo \"second=$?\"\n";
    out = run(dir, "a", stopTuneAt(tune, dir / "err_a", "[3/", cache, waitFor(dir / "err_a", "[1/") + second));
    std::string err = readFile(dir / "err_a");
    INFO(out << "\n" << err << "\n" << readFile(dir / "second.txt"));
    CHECK_THAT(out, Contains("second=1"));
    CHECK_THAT(readFile(dir / "second.txt"), Contains("tune.lock: another run (PID"));
    CHECK_THAT(out, Contains("status=143"));
    CHECK_THAT(err, Contains("[2/") && Contains("reference (exact, crop"));
    requireTidyCache(cache);

    // Another particle file under the same scene: nothing measured before is reused.
    fs::copy_file(dump("9"), dir / "parts.bin", fs::copy_options::overwrite_existing);
    out = run(dir, "b", stopTuneAt(tune, dir / "err_b", "[2/", cache));
    err = readFile(dir / "err_b");
    INFO(out << "\n" << err);
    CHECK_THAT(out, Contains("status=143"));
    CHECK(err.find("(cached)") == std::string::npos);
    // The first file again: its references are read back, not rendered.
    fs::copy_file(dump("7"), dir / "parts.bin", fs::copy_options::overwrite_existing);
    out = run(dir, "c", stopTuneAt(tune, dir / "err_c", "[3/", cache));
    err = readFile(dir / "err_c");
    INFO(out << "\n" << err);
    std::istringstream lines(err);
    std::size_t cached = 0;
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("tune: [1/", 0) == 0 || line.rfind("tune: [2/", 0) == 0) cached += line.find("(cached)") != std::string::npos;
    CHECK(cached == 2);

    // A damaged entry (a truncated reference): the user's error, naming it; it stays.
    std::vector<fs::path> references;
    for (const auto& e : fs::directory_iterator(cache))
        if (e.path().string().size() > 8 && e.path().string().ends_with(".ref.exr")) references.push_back(e.path());
    REQUIRE(references.size() >= 3);  // two crops of the first file, one or two of the second
    for (const fs::path& r : references) fs::resize_file(r, 2000);
    REQUIRE(runCommand(tune, out) == 1);
    CHECK_THAT(out, Contains(".ref.exr (reference (exact, crop") && Contains("cannot be read") &&
                        Contains("delete it and run tune again to measure it again"));
    for (const fs::path& r : references) CHECK(fs::file_size(r) == 2000);
}
