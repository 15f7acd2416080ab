// Faults around the outputs, with real processes: a full disk (a file-size
// limit, so no root is needed) and an output path that cannot be a
// directory. A failed write leaves the previous complete file untouched and
// no partial or temporary file behind.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/test_scenes.h"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

namespace {

std::string render(const fs::path& exr) {
    return accretion::test::programPath() + " render " + ACCRETION_SOURCE_DIR +
           "/scenes/quickstart.toml --quiet --frames 0:1 -D camera.width=320 -D camera.height=180 "
           "-D particles.count=500 -D render.samples=2 -o " + exr.string();
}

}  // namespace

TEST_CASE("a full disk: a clear error, exit 1, the previous complete outputs kept, nothing partial", "[cli][fault]") {
    const fs::path dir = accretion::test::scratchDir("fault_disk_full");
    const fs::path exr = dir / "x.exr";
    std::string out;
    REQUIRE(accretion::test::runCommand(render(exr), out) == 0);
    const std::string before = accretion::test::readFile(exr);
    REQUIRE(before.size() > 16 * 1024);
    std::size_t filesBefore = 0;
    for (const auto& e : fs::directory_iterator(dir)) filesBefore += e.is_regular_file();
    // 16 KiB file-size limit: the EXR cannot be written (SIGXFSZ ignored, so writes fail with EFBIG).
    const int status = accretion::test::runCommand("sh -c \"trap '' XFSZ; ulimit -f 16; " + render(exr) + "\"", out);
    INFO(out);
    CHECK(status == 1);
    CHECK_THAT(out, Contains(exr.string() + ": cannot write EXR"));
    CHECK(accretion::test::readFile(exr) == before);
    std::size_t filesAfter = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        filesAfter += e.is_regular_file();
        CHECK(e.path().filename().string().find(".tmp") == std::string::npos);
    }
    CHECK(filesAfter == filesBefore);
}

TEST_CASE("an output directory that cannot exist: a clear error and exit 1", "[cli][fault]") {
    const fs::path dir = accretion::test::scratchDir("fault_not_a_dir");
    std::ofstream(dir / "file") << "x";
    std::string out;
    CHECK(accretion::test::runCommand(render(dir / "file" / "x.exr"), out) == 1);
    CHECK_THAT(out, Contains("cannot create output directory"));
}

TEST_CASE("two runs to one output: the second is refused naming the first's PID, the checkpoint survives",
          "[cli][fault][lock]") {
    const fs::path dir = accretion::test::scratchDir("fault_two_runs");
    const std::string slow = accretion::test::programPath() + " render " + ACCRETION_SOURCE_DIR +
                             "/scenes/quickstart.toml --quiet --frames 0:1 -D camera.width=320 -D camera.height=180 "
                             "-D particles.count=20000 --estimator uniform --spp 2048 --checkpoint-every 0 -o " +
                             (dir / "x.exr").string();
    // The first run in the background; once it holds the lock, a second run
    // to the same outputs; then the first is interrupted (it checkpoints),
    // and a third run without --resume must leave that checkpoint alone.
    const std::string script = slow + " > /dev/null 2> " + (dir / "first.err").string() + " & P=$!\n" +
                               "i=0; while [ ! -s " + (dir / "x.lock").string() + " ] && [ $i -lt 600 ]; do sleep 0.05; i=$((i+1)); done\n" +
                               slow + " 2>&1 > /dev/null; echo \"second=$? first_pid=$P\"\n" +
                               "kill -INT $P; wait $P; echo \"first=$?\"\n" +
                               slow + " 2>&1 > /dev/null; echo \"third=$?\"\n";
    std::ofstream(dir / "script.sh") << script;
    std::string out;
    accretion::test::runCommand("sh " + (dir / "script.sh").string() + " 2>&1", out);
    INFO(out << "\nfirst run:\n" << accretion::test::readFile(dir / "first.err"));
    const auto pidAt = out.find("first_pid=");
    REQUIRE(pidAt != std::string::npos);
    const std::string pid = out.substr(pidAt + 10, out.find('\n', pidAt) - pidAt - 10);
    CHECK_THAT(out, Contains("x.lock: another run (PID " + pid + ") is writing these outputs"));
    CHECK_THAT(out, Contains("second=1 "));
    CHECK_THAT(out, Contains("first=130"));
    CHECK_THAT(out, Contains("a checkpoint of an interrupted run is here"));
    CHECK_THAT(out, Contains("third=1"));
    CHECK(fs::exists(dir / "x.checkpoint"));
    CHECK(!fs::exists(dir / "x.exr"));
    CHECK(!fs::exists(dir / "x.lock"));  // released by the interrupted run
    // The checkpoint the first run named still resumes to a complete image.
    CHECK(accretion::test::runCommand(slow + " --resume 2>&1", out) == 0);
    CHECK(fs::exists(dir / "x.exr"));
    CHECK(!fs::exists(dir / "x.checkpoint"));
    CHECK(!fs::exists(dir / "x.lock"));
}

TEST_CASE("restir stopped by SIGTERM or SIGINT: the frames done are whole with their previews, no lock, no temporary",
          "[cli][fault][signal]") {
    const std::string signal = GENERATE("TERM", "INT");
    const fs::path dir = accretion::test::scratchDir("fault_restir_" + signal);
    // Many frames: the signal comes once frame 0 is written, long before the last.
    const std::string run = accretion::test::programPath() + " render " + ACCRETION_SOURCE_DIR +
                            "/scenes/quickstart.toml --quiet --frames 0:400 -D camera.width=160 -D camera.height=90 "
                            "-D particles.count=5000 --estimator restir -o " + (dir / "r.{frame}.exr").string();
    const std::string script = run + " > /dev/null 2> " + (dir / "err").string() + " & P=$!\n" +
                               "i=0; while [ ! -e " + (dir / "r.0000.Lr.png").string() + " ] && [ $i -lt 1200 ]; do sleep 0.05; i=$((i+1)); done\n" +
                               "kill -" + signal + " $P; wait $P; echo \"status=$?\"\n";
    std::ofstream(dir / "script.sh") << script;
    std::string out;
    accretion::test::runCommand("sh " + (dir / "script.sh").string() + " 2>&1", out);
    const std::string err = accretion::test::readFile(dir / "err");
    INFO(out << "\n" << err);
    CHECK_THAT(out, Contains(signal == "TERM" ? "status=143" : "status=130"));
    CHECK_THAT(err, Contains("SIG" + signal + ": stopped before frame") && Contains("render the rest with --frames"));
    // Every frame written is whole: its EXR, both previews; nothing else is left.
    std::size_t frames = 0;
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string name = e.path().filename().string();
        CHECK(name.front() != '.');                    // no hidden temporary
        CHECK(e.path().extension() != ".lock");
        if (e.path().extension() == ".exr") {
            ++frames;
            const std::string stem = e.path().stem().string();
            CHECK(fs::exists(dir / (stem + ".png")));
            CHECK(fs::exists(dir / (stem + ".Lr.png")));
        }
    }
    CHECK(frames >= 1);
    CHECK(frames < 400);
}
