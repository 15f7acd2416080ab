// Batch-render robustness with real processes: checkpoints and --resume
// (bit-identical to an uninterrupted run), refusal of foreign or corrupted
// checkpoints, kill -9 mid-write and after each write (never a broken output), and shards
// run with GNU parallel merged into the image of one run.
#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <optional>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>

#include <nlohmann/json.hpp>
#include <OpenImageIO/imageio.h>

#include "accretion/io/accumulation_file.h"
#include "accretion/io/exr_output.h"
#include "support/statistics.h"
#include "support/test_scenes.h"

extern char** environ;

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using accretion::test::runCommand;

namespace {

/// quickstart at 160x90, 2 frames of `uniform` at `spp` samples: spp/8
/// chunks a frame (4096 samples: about 0.8 s on 2 cores).
std::string renderCommand(const fs::path& dir, const std::string& extra = "", int spp = 4096,
                          const std::string& estimator = "uniform") {
    return accretion::test::programPath() + " render " + ACCRETION_SOURCE_DIR +
           "/scenes/quickstart.toml --quiet --frames 0:2 -D camera.width=160 -D camera.height=90 "
           "-D particles.count=2000 --estimator " + estimator + " --spp " + std::to_string(spp) + " -o " +
           (dir / "{scene}.{frame}.exr").string() + " " + extra;
}

/// A running process (sh -c "exec ..."): its pid is the command's.
class Process {
public:
    explicit Process(const std::string& command) {
        const std::string line = "exec " + command + " >/dev/null 2>&1";
        char* argv[] = {const_cast<char*>("sh"), const_cast<char*>("-c"), const_cast<char*>(line.c_str()), nullptr};
        REQUIRE(posix_spawn(&pid_, "/bin/sh", nullptr, nullptr, argv, environ) == 0);
    }
    void signal(int s) const { ::kill(pid_, s); }
    /// Exit status, or 128 + signal when killed.
    int wait() {
        if (!status_) reap(0);
        return *status_;
    }
    bool running() { return !status_ && !reap(WNOHANG); }
    /// Freezes the process where it is (SIGSTOP): true when it was still
    /// running, so that a signal sent now lands mid-run; false when it had
    /// already exited.
    bool freeze() {
        if (status_) return false;
        ::kill(pid_, SIGSTOP);
        int status = 0;
        ::waitpid(pid_, &status, WUNTRACED);
        if (WIFSTOPPED(status)) return true;
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return false;
    }

private:
    /// Waits (flags 0) or polls (WNOHANG) for the exit; true once it has exited.
    bool reap(int flags) {
        int status = 0;
        if (::waitpid(pid_, &status, flags) != pid_) return false;
        status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
        return true;
    }
    pid_t pid_ = 0;
    std::optional<int> status_;
};

/// Every pixel of every channel, bit for bit.
bool sameImage(const fs::path& a, const fs::path& b) {
    const accretion::RawExr x = accretion::readRawExr(a), y = accretion::readRawExr(b);
    return x.width == y.width && x.height == y.height && x.channels == y.channels && x.bits == y.bits;
}

/// Problems of the outputs in `dir`: each file must be complete and
/// readable (temporaries of a killed writer are not outputs).
std::vector<std::string> brokenFiles(const fs::path& dir, std::size_t& checked) {
    std::vector<std::string> broken;
    for (const auto& e : fs::directory_iterator(dir)) {
        const fs::path p = e.path();
        const std::string name = p.filename().string();
        if (name.front() == '.' && name.find(".tmp") != std::string::npos) continue;
        ++checked;
        try {
            const std::string ext = p.extension().string();
            if (ext == ".exr") accretion::readRawExr(p);
            else if (ext == ".png") {
                auto in = OIIO::ImageInput::open(p.string());
                std::vector<unsigned char> px(in ? in->spec().image_bytes() : 0);
                if (!in || !in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::UINT8, px.data()))
                    throw std::runtime_error("unreadable PNG");
            } else if (ext == ".json") {
                const nlohmann::json parsed = nlohmann::json::parse(accretion::test::readFile(p));  // throws if broken
                (void)parsed;
            } else if (ext == ".checkpoint" || ext == ".acc") accretion::readAccumulationFile(p);
            else if (ext == ".toml") {
                if (accretion::test::readFile(p).find("[render]") == std::string::npos) throw std::runtime_error("truncated");
            } else if (ext == ".lock") {
                // Left by a killed run (the kernel released its flock): a PID,
                // or empty when killed between creating and writing it.
                const std::string pid = accretion::test::readFile(p);
                if (pid.find_first_not_of("0123456789\n") != std::string::npos) throw std::runtime_error("not a PID");
            } else throw std::runtime_error("unexpected file");
        } catch (const std::exception& ex) {
            broken.push_back(name + ": " + ex.what());
        }
    }
    return broken;
}

}  // namespace

TEST_CASE("SIGTERM writes a checkpoint and --resume gives the uninterrupted image bit for bit", "[cli][resume][long]") {
    // Sweeps go band by band (every chunk of 8 rows at once): the checkpoint
    // stops part-way down the frame; split's near field is found again on resume.
    const std::string estimator = GENERATE("uniform", "split");
    const int spp = estimator == "split" ? 1024 : 4096;
    INFO(estimator);
    const fs::path ref = accretion::test::scratchDir("resume_reference_" + estimator);
    const fs::path dir = accretion::test::scratchDir("resume_interrupted_" + estimator);
    std::string out;
    REQUIRE(runCommand(renderCommand(ref, "", spp, estimator), out) == 0);

    Process p(renderCommand(dir, "--checkpoint-every 0.05", spp, estimator));
    // Interrupt once a checkpoint exists (the run is part-way), before it ends.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!fs::exists(dir / "quickstart.checkpoint") && p.running() && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    p.signal(SIGTERM);
    const int status = p.wait();
    REQUIRE(status == 128 + SIGTERM);  // stopped, not finished
    REQUIRE(fs::exists(dir / "quickstart.checkpoint"));
    CHECK_FALSE(fs::exists(dir / "quickstart.stats.json"));

    // Without --resume the checkpoint is kept and the run refused.
    CHECK(runCommand(renderCommand(dir, "", spp, estimator), out) == 1);
    CHECK_THAT(out, Contains("quickstart.checkpoint: a checkpoint of an interrupted run is here"));

    REQUIRE(runCommand(renderCommand(dir, "--resume", spp, estimator), out) == 0);
    INFO(out);
    for (const char* f : {"quickstart.0000.exr", "quickstart.0001.exr"}) {
        INFO(f);
        CHECK(sameImage(ref / f, dir / f));
    }
    CHECK_FALSE(fs::exists(dir / "quickstart.checkpoint"));  // done: removed
    const auto stats = nlohmann::json::parse(accretion::test::readFile(dir / "quickstart.stats.json"));
    CHECK(stats["frames"].size() == 2);
}

TEST_CASE("a checkpoint of other settings, or a corrupted one, is refused with a clear error", "[cli][resume]") {
    const fs::path dir = accretion::test::scratchDir("resume_refused");
    Process p(renderCommand(dir, "--checkpoint-every 0.02"));
    while (!fs::exists(dir / "quickstart.checkpoint") && p.running())
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    p.signal(SIGINT);
    REQUIRE(p.wait() == 128 + SIGINT);
    const fs::path ckpt = dir / "quickstart.checkpoint";
    const std::string good = accretion::test::readFile(ckpt);
    std::string out;

    CHECK(runCommand(renderCommand(dir, "--resume -D render.seed=5"), out) == 1);
    CHECK_THAT(out, Contains(ckpt.string() + ": checkpoint of other settings: [render] `seed = 0` there, `seed = 5` here"));

    std::string bad = good;
    bad[bad.size() / 2] ^= 0x5a;
    std::ofstream(ckpt, std::ios::binary) << bad;
    CHECK(runCommand(renderCommand(dir, "--resume"), out) == 1);
    CHECK_THAT(out, Contains(ckpt.string() + ": corrupted accumulation file (checksum mismatch)"));

    std::ofstream(ckpt, std::ios::binary) << good.substr(0, good.size() / 3);
    CHECK(runCommand(renderCommand(dir, "--resume"), out) == 1);
    CHECK_THAT(out, Contains(ckpt.string() + ": corrupted accumulation file"));

    std::ofstream(ckpt, std::ios::binary) << "not a checkpoint";
    CHECK(runCommand(renderCommand(dir, "--resume"), out) == 1);
    CHECK_THAT(out, Contains(ckpt.string() + ": not an accretion accumulation file"));
    // Nothing was overwritten by the refused runs.
    CHECK(accretion::test::readFile(ckpt) == "not a checkpoint");
}

/// What a run has written to `dir` so far: each output's size and time, and
/// the writers' temporaries (named by their process: a killed run's stay).
struct DirState {
    std::map<std::string, std::pair<std::uintmax_t, fs::file_time_type>> outputs;
    std::set<std::string> temporaries;
};
DirState dirState(const fs::path& dir) {
    DirState state;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.front() == '.' && name.find(".tmp") != std::string::npos) {
            state.temporaries.insert(name);
            continue;
        }
        const auto size = fs::file_size(e.path(), ec);
        const auto time = fs::last_write_time(e.path(), ec);
        if (!ec) state.outputs[name] = {size, time};
    }
    return state;
}

/// The moments a run is killed at, in turn: while a file is being written
/// (its temporary exists), and just after a checkpoint or output changed.
enum class KillMoment { midWrite, afterWrite };

/// Polls `dir` until the moment has come `n` times or the process exits;
/// true if it came.
bool awaitMoment(Process& p, const fs::path& dir, KillMoment moment, int n) {
    DirState last = dirState(dir);
    const std::set<std::string> stale = last.temporaries;  // of killed runs
    bool wasWriting = false;
    while (p.running()) {
        const DirState now = dirState(dir);
        const bool writing = std::any_of(now.temporaries.begin(), now.temporaries.end(),
                                         [&](const std::string& t) { return !stale.count(t); });
        const bool came = moment == KillMoment::midWrite ? writing && !wasWriting : now.outputs != last.outputs;
        wasWriting = writing;
        last = now;
        if (came && --n == 0) return true;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
}

TEST_CASE("kill -9 mid-write and after each write never leaves a broken file, and resuming still gives the same image",
          "[cli][resume][fault][long]") {
    const fs::path ref = accretion::test::scratchDir("kill_reference");
    const fs::path dir = accretion::test::scratchDir("kill_trials");
    std::string out;
    // About 6 s in Release: room for many kills. Under the sanitizers (a
    // seed divisor; 10 kills there) the program runs 2-3x slower, and half
    // the samples leave it as much time to be killed in.
    const int spp = accretion::test::fullStatisticalPower() ? 32768 : 16384;
    REQUIRE(runCommand(renderCommand(ref, "", spp), out) == 0);

    // Longer campaigns: ACCRETION_KILL_TRIALS=N.
    const char* env = std::getenv("ACCRETION_KILL_TRIALS");
    const int maxTrials = env ? std::atoi(env) : 24;
    int trials = 0, killedMidWrite = 0, killedAfterWrite = 0;
    std::size_t checked = 0;
    std::vector<std::string> broken;
    for (bool finished = false; !finished;) {
        Process p(renderCommand(dir, "--resume --checkpoint-every 0.03", spp));
        if (trials < maxTrials) {
            // Each kill comes at the 1st to 4th write of the run (so that
            // later trials get further) and lands on a process frozen mid-run.
            const KillMoment moment = trials % 2 ? KillMoment::afterWrite : KillMoment::midWrite;
            REQUIRE(awaitMoment(p, dir, moment, 1 + (trials / 2) % 4));
            REQUIRE(p.freeze());
            p.signal(SIGKILL);
            p.signal(SIGCONT);
            REQUIRE(p.wait() == 128 + SIGKILL);
            ++(moment == KillMoment::midWrite ? killedMidWrite : killedAfterWrite);
            ++trials;
        } else {
            REQUIRE(p.wait() == 0);
            finished = true;
        }
        for (const std::string& b : brokenFiles(dir, checked)) broken.push_back(b);
    }
    INFO(trials << " trials, " << checked << " files checked");
    CHECK(killedMidWrite == maxTrials / 2);
    CHECK(killedAfterWrite == maxTrials - maxTrials / 2);
    for (const std::string& b : broken) UNSCOPED_INFO(b);
    CHECK(broken.empty());
    for (const char* f : {"quickstart.0000.exr", "quickstart.0001.exr"}) {
        INFO(f);
        CHECK(sameImage(ref / f, dir / f));
    }
}

TEST_CASE("shards run with GNU parallel merge into the image of one run", "[cli][shard]") {
    const fs::path dir = accretion::test::scratchDir("shards");
    std::string out;
    REQUIRE(runCommand("parallel --version", out) == 0);
    const std::string scene = std::string(ACCRETION_SOURCE_DIR) + "/scenes/quickstart.toml";
    for (const char* estimator : {"exact", "uniform", "ris"}) {
        INFO(estimator);
        const std::string common = accretion::test::programPath() + " render " + scene +
                                   " --quiet --frames 1 -D camera.width=96 -D camera.height=54 -D particles.count=1500 "
                                   "--spp 64 --estimator " + estimator;
        const fs::path one = dir / (std::string(estimator) + ".one.exr");
        REQUIRE(runCommand(common + " -o " + one.string(), out) == 0);
        // -I@@: GNU parallel's {} would clash with accretion's {scene}/{frame} patterns.
        const std::string pattern = (dir / (std::string(estimator) + ".{frame}.exr")).string();
        REQUIRE(runCommand("parallel --will-cite -j2 -I@@ " + common + " -o '" + pattern + "' --shard @@/3 ::: 0 1 2", out) == 0);
        const fs::path merged = dir / (std::string(estimator) + ".merged.exr");
        // Named as --shard I/3 gives them (shard0of3..shard2of3); given out of order: the merge sums in shard order.
        const auto shard = [&](int i) { return (dir / (std::string(estimator) + ".0001.shard" + std::to_string(i) + "of3.exr")).string(); };
        REQUIRE(runCommand(accretion::test::programPath() + " merge " + shard(2) + " " + shard(0) + " " + shard(1) + " -o " + merged.string(), out) == 0);
        INFO(out);
        CHECK(sameImage(one, merged));
        // Beside it, the settings the shards were rendered with (what compare's
        // worst-pixel commands render with).
        const fs::path mergedSettings = fs::path(merged).replace_extension(".settings.toml");
        REQUIRE(fs::exists(mergedSettings));
        CHECK(accretion::test::readFile(mergedSettings) ==
              accretion::test::readFile(dir / (std::string(estimator) + ".shard0of3.settings.toml")));

        // A missing or repeated shard is refused.
        CHECK(runCommand(accretion::test::programPath() + " merge " + shard(0) + " " + shard(1) + " -o " + (dir / "x.exr").string(), out) == 1);
        CHECK_THAT(out, Contains("shard(s) 2/3 missing"));
        CHECK(runCommand(accretion::test::programPath() + " merge " + shard(0) + " " + shard(0) + " " + shard(1) + " -o " + (dir / "x.exr").string(), out) == 1);
        CHECK_THAT(out, Contains("given twice"));
        CHECK_FALSE(fs::exists(dir / "x.exr"));
    }
}
