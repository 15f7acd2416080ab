// The output guard, the lock and the stale-temporary sweep, on real files.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include <sys/stat.h>
#include <unistd.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "support/test_scenes.h"

namespace fs = std::filesystem;
using namespace accretion;
using Catch::Matchers::Contains;

namespace {
std::string refusal(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "accepted";
}
}  // namespace

TEST_CASE("the guard finds an input under any name and refuses non-files", "[core][output]") {
    const fs::path dir = accretion::test::scratchDir("output_guard");
    std::ofstream(dir / "in.toml") << "x";
    fs::create_hard_link(dir / "in.toml", dir / "hard.exr");
    fs::create_symlink(dir / "in.toml", dir / "soft.exr");
    fs::create_directory(dir / "d.exr");
    REQUIRE(::mkfifo((dir / "fifo.exr").c_str(), 0644) == 0);
    OutputGuard guard;
    guard.addInput(dir / "in.toml");
    guard.addInput(dir / "missing.toml");  // ignored
    CHECK_THAT(refusal([&] { guard.check(dir / "in.toml", "-o"); }), Contains("an input of this run"));
    CHECK_THAT(refusal([&] { guard.check(dir / "hard.exr", "-o"); }), Contains("the same file as the input"));
    CHECK_THAT(refusal([&] { guard.check(dir / "soft.exr", "-o"); }), Contains("the same file as the input"));
    CHECK_THAT(refusal([&] { guard.check(dir / "." / "in.toml", "-o"); }), Contains("in.toml"));
    CHECK_THAT(refusal([&] { guard.check(dir / "d.exr", "-o"); }), Contains("is a directory"));
    CHECK_THAT(refusal([&] { guard.check(dir / "fifo.exr", "-o"); }), Contains("is a FIFO"));
    CHECK_THAT(refusal([&] { guard.check("/dev/null", "-o"); }), Contains("is a device"));
    CHECK(refusal([&] { guard.check(dir / "new.exr", "-o"); }) == "accepted");
    // Every atomic write refuses a non-file too, and leaves it as it was.
    CHECK_THAT(refusal([&] { writeFileAtomic(dir / "fifo.exr", "bytes"); }), Contains("is a FIFO"));
    CHECK(fs::is_fifo(dir / "fifo.exr"));
    // Over-long names and paths: a short message, not the whole path.
    const std::string longName(300, 'n');
    const std::string msg = refusal([&] { guard.check(dir / (longName + ".exr"), "-o"); });
    CHECK_THAT(msg, Contains("a name of 304 bytes"));
    CHECK(msg.size() < 300);
}

TEST_CASE("the output lock: one holder, the PID in the refusal, released on destruction", "[core][output]") {
    const fs::path dir = accretion::test::scratchDir("output_lock");
    {
        const OutputLock lock(dir / "x.lock");
        CHECK(fs::exists(dir / "x.lock"));
        // flock locks belong to open file descriptions: a second open in this
        // process conflicts as another process's would.
        CHECK_THAT(refusal([&] { OutputLock again(dir / "x.lock"); }),
                   Contains("another run (PID " + std::to_string(::getpid()) + ")"));
    }
    CHECK(!fs::exists(dir / "x.lock"));
    // A lock file left by a killed run (no holder) is taken over.
    std::ofstream(dir / "y.lock") << "999999\n";
    { const OutputLock lock(dir / "y.lock"); }
    CHECK(!fs::exists(dir / "y.lock"));
}

TEST_CASE("stale temporaries: only a dead writer's own are removed, odd names left alone", "[core][output]") {
    const fs::path dir = accretion::test::scratchDir("stale_temporaries");
    // A PID that cannot be alive (above pid_max), one out of pid_t's range,
    // and names that only look like temporaries.
    for (const char* name : {".x.tmp4194305.exr", ".x.tmp99999999999999999999999.exr", ".x.tmp-5.exr", ".x.tmp.exr",
                             ".x.tmpabc", "x.tmp1.exr"})
        std::ofstream(dir / name) << "x";
    const std::string mine = ".x.tmp" + std::to_string(::getpid()) + ".exr";
    std::ofstream(dir / mine) << "x";
    CHECK(removeStaleTemporaries(dir) == 1);
    CHECK(!fs::exists(dir / ".x.tmp4194305.exr"));
    for (const char* name : {".x.tmp99999999999999999999999.exr", ".x.tmp-5.exr", ".x.tmp.exr", ".x.tmpabc", "x.tmp1.exr"})
        CHECK(fs::exists(dir / name));
    CHECK(fs::exists(dir / mine));  // this process's own
}
