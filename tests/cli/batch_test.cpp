// accretion batch with real processes: one failing job does not stop the
// others, the summary lists every outcome, --resume skips finished jobs,
// scene x frame x seed jobs from the command line, bad jobs files refused.
#include <catch2/catch.hpp>

#include <chrono>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/cli.h"
#include "support/test_scenes.h"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using accretion::test::kBin;
using accretion::test::runCommand;

namespace {

nlohmann::json readJson(const fs::path& file) { return nlohmann::json::parse(accretion::test::readFile(file)); }

}  // namespace

TEST_CASE("batch: a failing job does not stop the others, the summary lists each outcome, --resume skips done jobs",
          "[cli][batch]") {
    const fs::path dir = accretion::test::scratchDir("batch_jobs");
    const std::string scene = accretion::test::smallDiskScene();
    std::ofstream(dir / "jobs.toml") << "[batch]\noutput_dir = \"out\"\n\n"
                                     << "[[job]]\nname = \"a\"\nscene = \"" << scene << "\"\nestimator = \"uniform\"\nspp = 4\n\n"
                                     << "[[job]]\nname = \"bad\"\nscene = \"" << scene << "\"\ndefine = [\"shading.dmin=-1\"]\n\n"
                                     << "[[job]]\nname = \"c\"\nscene = \"" << scene << "\"\nseed = 3\nestimator = \"power\"\nspp = 4\n";
    std::string out;
    const std::string cmd = kBin + " batch " + (dir / "jobs.toml").string() + " --quiet";
    const auto start = std::chrono::steady_clock::now();
    REQUIRE(runCommand(cmd, out) == 4);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    INFO(out);
    const auto summary = readJson(dir / "out" / "batch.json");
    REQUIRE(summary["jobs"].size() == 3);
    CHECK(summary["counts"]["ok"] == 2);
    CHECK(summary["counts"]["failed"] == 1);
    for (const auto& j : summary["jobs"]) {
        INFO(j.dump());
        CHECK(j["seconds"].get<double>() <= wall);  // a job's time is part of the batch's
        if (j["name"] == "bad") {
            CHECK(j["outcome"] == "failed");
            CHECK(j["exit_code"] == 1);
            CHECK_THAT(j["error"].get<std::string>(), Contains("shading.dmin"));
            continue;
        }
        CHECK(j["outcome"] == "ok");
        const std::string exr = j["outputs"]["frames"][0]["exr"];
        CHECK(fs::exists(exr));
        CHECK(fs::exists(j["outputs"]["stats"].get<std::string>()));
        // The time the summary gives is the job's own: its frame's time is inside it.
        const auto stats = readJson(j["outputs"]["stats"].get<std::string>());
        CHECK(stats["frames"][0]["seconds"].get<double>() <= j["seconds"].get<double>());
    }
    CHECK_FALSE(fs::exists(dir / "out" / "bad"));  // the failed job wrote nothing

    // Rerun with --resume: a and c are not run again, bad is (and fails again).
    const auto before = fs::last_write_time(dir / "out" / "a" / "small_disk.0000.exr");
    REQUIRE(runCommand(cmd + " --resume", out) == 4);
    const auto again = readJson(dir / "out" / "batch.json");
    for (const auto& j : again["jobs"]) {
        INFO(j.dump());
        if (j["name"] == "bad") CHECK(j["outcome"] == "failed");
        else CHECK(j.contains("skipped"));
    }
    CHECK(fs::last_write_time(dir / "out" / "a" / "small_disk.0000.exr") == before);
}

TEST_CASE("batch: scene x frame x seed jobs from the command line", "[cli][batch]") {
    const fs::path dir = accretion::test::scratchDir("batch_matrix");
    std::string out;
    REQUIRE(runCommand(kBin + " batch --quiet --scene " + accretion::test::smallDiskScene() +
                           " --frames 0:2 --seeds 5:7 --estimator uniform --spp 2 -j 2 --output-dir " + (dir / "out").string(),
                       out) == 0);
    INFO(out);
    const auto summary = readJson(dir / "out" / "batch.json");
    REQUIRE(summary["jobs"].size() == 4);
    for (const char* name : {"small_disk-f0-s5", "small_disk-f0-s6", "small_disk-f1-s5", "small_disk-f1-s6"}) {
        INFO(name);
        const fs::path stats = dir / "out" / name / "small_disk.stats.json";
        REQUIRE(fs::exists(stats));
        CHECK(readJson(stats)["seed"] == (std::string(name).back() == '5' ? 5 : 6));
    }
    // Different seeds, different images.
    CHECK(accretion::test::readFile(dir / "out" / "small_disk-f0-s5" / "small_disk.0000.exr") !=
          accretion::test::readFile(dir / "out" / "small_disk-f0-s6" / "small_disk.0000.exr"));
}

TEST_CASE("batch: a bad jobs file is refused with its line, nothing run", "[cli][batch]") {
    const fs::path dir = accretion::test::scratchDir("batch_bad");
    const std::string scene = accretion::test::smallDiskScene();
    struct Case {
        const char* text;
        const char* error;
    };
    const Case c = GENERATE(Case{"[[job]]\nscene = \"S\"\nsped = 3\n", "jobs.toml:3: job.sped: unknown key"},
                            Case{"[[job]]\nscene = \"S\"\nseed = -1\n", "jobs.toml:3: job.seed: expected an integer"},
                            Case{"[[job]]\nscene = \"S\"\nspp = \"many\"\n", "jobs.toml:3: job.spp: expected an integer"},
                            Case{"[[job]]\nname = \"x\"\nscene = \"S\"\n[[job]]\nname = \"x\"\nscene = \"S\"\n", "two jobs named x"},
                            Case{"[[job]]\nscene = \"missing.toml\"\n", "missing.toml: job missing: scene file not found"},
                            Case{"[jobs]\n", "jobs.toml:1: jobs: unknown table"},
                            Case{"[batch]\n", "no [[job]] tables"},
                            Case{"[[job]\n", "jobs.toml:1:"});
    std::string text = c.text;
    for (auto p = text.find("\"S\""); p != std::string::npos; p = text.find("\"S\"")) text.replace(p, 3, "\"" + scene + "\"");
    std::ofstream(dir / "jobs.toml") << text;
    std::string out;
    CHECK(runCommand("cd " + dir.string() + " && " + kBin + " batch jobs.toml --output-dir out", out) == 1);
    CHECK_THAT(out, Contains(c.error));
    CHECK_FALSE(fs::exists(dir / "out"));
}

TEST_CASE("batch: the example interrupted in its first job resumes to success, --output-dir overrides the file",
          "[cli][batch][resume][long]") {
    const fs::path dir = accretion::test::scratchDir("batch_example_resume");
    const std::string jobs = std::string(ACCRETION_SOURCE_DIR) + "/scenes/batch/example_jobs.toml";
    const std::string cmd = kBin + " batch " + jobs + " --quiet --output-dir " + (dir / "out").string();
    const std::string script = cmd + " > /dev/null 2>&1 & P=$!\n" + "i=0; while [ ! -s " +
                               (dir / "out" / "quickstart-exact-f0.log").string() +
                               " ] && [ ! -f " + (dir / "out" / "quickstart-exact-f0.log").string() +
                               " ] && [ $i -lt 600 ]; do sleep 0.05; i=$((i+1)); done\nsleep 0.3\nkill -INT $P; wait $P; echo \"first=$?\"\n";
    std::ofstream(dir / "script.sh") << script;
    std::string out;
    runCommand("sh " + (dir / "script.sh").string() + " 2>&1", out);
    INFO(out);
    CHECK_THAT(out, Contains("first=130"));
    const auto stopped = readJson(dir / "out" / "batch.json");
    CHECK(stopped["counts"].value("ok", 0) < 3);
    // The jobs that never started have nothing to resume: they start afresh
    // (restir among them), the interrupted one continues its checkpoint.
    REQUIRE(runCommand(cmd + " --resume", out) == 0);
    const auto done = readJson(dir / "out" / "batch.json");
    CHECK(done["counts"]["ok"] == 3);
    for (const auto& j : done["jobs"]) {
        INFO(j.dump());
        CHECK(j["outcome"] == "ok");
    }
    CHECK(fs::exists(dir / "out" / "quickstart-restir-f0-2" / "quickstart.0002.exr"));
    // Everything under the command line's --output-dir, nothing where the file says.
    std::ofstream(dir / "jobs.toml") << "[batch]\noutput_dir = \"from_file\"\n[[job]]\nname = \"j\"\nscene = \""
                                     << accretion::test::smallDiskScene() << "\"\nestimator = \"uniform\"\nspp = 1\n";
    REQUIRE(runCommand(kBin + " batch " + (dir / "jobs.toml").string() + " --quiet --output-dir " + (dir / "cli").string(), out) == 0);
    CHECK(fs::exists(dir / "cli" / "batch.json"));
    CHECK(fs::exists(dir / "cli" / "j" / "small_disk.0000.exr"));
    CHECK(!fs::exists(dir / "from_file"));
}
