// accretion batch: many renders (a jobs file, or scene x frame x seed from
// the command line), each in its own process so that one failing or
// crashing job does not stop the others; a summary JSON lists every job's
// outcome, time and outputs, rewritten atomically after each job.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/stop_signal.h"
#include "accretion/core/version.h"
#include "accretion/core/atomic_file.h"
#include "accretion/scene/toml_limits.h"
#include "accretion/io/stats_writer.h"
#include "child_process.h"
#include "commands.h"
#include "jobs_file.h"

extern char** environ;

namespace accretion::cmd {
namespace {


struct BatchArgs {
    std::string jobsFile;
    std::vector<std::string> scenes;
    std::string frames, seeds, estimator, outputDir = "out/batch", summary;
    std::optional<std::uint32_t> spp;
    std::vector<std::string> defines;
    int parallel = 1;
    int threads = 0;
    bool resume = false, quiet = false;
    bool outputDirGiven = false, parallelGiven = false;  ///< on the command line: the file's are ignored
};

/// "0:4" -> 0,1,2,3; "7" -> 7.
std::vector<std::uint64_t> parseRange(const std::string& text, const char* option) {
    const auto [a, b] = parseHalfOpen(text, option);
    if (b - a > 100000)
        throw InputError(fmt::format("command line {} {}: at most 100000 values (one job each)", option, text));
    std::vector<std::uint64_t> v;
    for (std::uint64_t x = a; x < b; ++x) v.push_back(x);
    return v;
}

/// Scene x frame x seed from the command line, one frame per job.
std::vector<Job> commandLineJobs(const BatchArgs& args) {
    if (args.scenes.empty()) throw InputError("command line: give a jobs file or --scene (with --frames, --seeds)");
    const std::vector<std::uint64_t> frames = args.frames.empty() ? std::vector<std::uint64_t>{} : parseRange(args.frames, "--frames");
    const std::vector<std::uint64_t> seeds = args.seeds.empty() ? std::vector<std::uint64_t>{} : parseRange(args.seeds, "--seeds");
    std::vector<Job> jobs;
    for (const std::string& scene : args.scenes) {
        const std::string stem = std::filesystem::path(scene).stem().string();
        for (std::size_t f = 0; f < std::max<std::size_t>(frames.size(), 1); ++f)
            for (std::size_t s = 0; s < std::max<std::size_t>(seeds.size(), 1); ++s) {
                Job j;
                j.scene = scene;
                if (!frames.empty()) j.frames = std::to_string(frames[f]);
                if (!seeds.empty()) j.seed = seeds[s];
                j.name = sanitizeJobName(fmt::format("{}{}{}", stem, frames.empty() ? "" : fmt::format("-f{}", frames[f]),
                                                     seeds.empty() ? "" : fmt::format("-s{}", seeds[s])));
                jobs.push_back(std::move(j));
            }
    }
    return jobs;
}

/// Where a job lists the files it wrote (render --outputs-file).
std::filesystem::path outputsFile(const BatchArgs& args, const Job& j) {
    return std::filesystem::path(args.outputDir) / (j.name + ".outputs.json");
}

/// The render command line of a job (this same executable).
std::vector<std::string> renderArgv(const Job& j, const BatchArgs& args) {
    std::vector<std::string> a = {"/proc/self/exe", "render", j.scene, "--quiet", "--outputs-file", outputsFile(args, j).string()};
    const std::string output = j.output.empty() ? (std::filesystem::path(args.outputDir) / j.name / "{scene}.{frame}.exr").string() : j.output;
    a.insert(a.end(), {"-o", output});
    if (!j.frames.empty()) a.insert(a.end(), {"--frames", j.frames});
    if (j.seed) a.insert(a.end(), {"--seed", std::to_string(*j.seed)});
    const std::string estimator = j.estimator.empty() ? args.estimator : j.estimator;
    if (!estimator.empty()) a.insert(a.end(), {"--estimator", estimator});
    if (const auto spp = j.spp ? j.spp : args.spp) a.insert(a.end(), {"--spp", std::to_string(*spp)});
    if (!j.shard.empty()) a.insert(a.end(), {"--shard", j.shard});
    if (args.threads > 0) a.insert(a.end(), {"--threads", std::to_string(args.threads)});
    if (args.resume) a.push_back("--resume");
    for (const std::string& d : args.defines) a.insert(a.end(), {"-D", d});
    for (const std::string& d : j.defines) a.insert(a.end(), {"-D", d});
    return a;
}

/// A running job: its process, log and start time.
struct Running {
    std::size_t job;
    pid_t pid;
    std::chrono::steady_clock::time_point start;
};

/// The files a finished job wrote, as its render listed them (--outputs-file).
nlohmann::json jobOutputs(const std::filesystem::path& manifest) {
    std::ifstream in(manifest);
    nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    if (j.is_discarded() || !j.is_object()) return nlohmann::json::object();
    return {{"stats", j.value("stats", "")}, {"frames", j.value("frames", nlohmann::json::array())}};
}

/// The jobs of the batch, checked before any runs: unique names, scenes that exist.
std::vector<Job> batchJobs(BatchArgs& args) {
    std::vector<Job> jobs;
    if (args.jobsFile.empty()) {
        jobs = commandLineJobs(args);
    } else {
        JobsFile file = readJobsFile(args.jobsFile);
        jobs = std::move(file.jobs);
        // The command line overrides the file.
        if (file.outputDir && !args.outputDirGiven) args.outputDir = *file.outputDir;
        if (file.parallel && !args.parallelGiven) args.parallel = *file.parallel;
    }
    if (!args.jobsFile.empty() && !args.scenes.empty())
        throw InputError("command line: give a jobs file or --scene, not both");
    if (args.parallel < 1) throw InputError("command line --parallel: expected at least 1");
    std::map<std::string, std::size_t> names;
    for (std::size_t k = 0; k < jobs.size(); ++k)
        if (!names.emplace(jobs[k].name, k).second)
            throw InputError(fmt::format("{}: two jobs named {}: outputs would collide", args.jobsFile.empty() ? "command line" : args.jobsFile, jobs[k].name));
    for (const Job& j : jobs)
        if (!std::filesystem::exists(j.scene)) throw InputError(fmt::format("{}: job {}: scene file not found", j.scene, j.name));
    return jobs;
}

/// A summary already there is this batch's (the same job names: run again
/// or resumed), never another's, whose record it would replace.
void refuseAnotherBatch(const std::string& summaryPath, const std::vector<Job>& jobs) {
    if (!std::filesystem::exists(summaryPath)) return;
    std::ifstream in(summaryPath);
    const nlohmann::json old = nlohmann::json::parse(in, nullptr, false);
    if (old.is_discarded() || !old.is_object())
        throw InputError(fmt::format("{}: not a batch summary (JSON); it would be replaced", summaryPath));
    std::set<std::string> before, now;
    for (const auto& j : old.value("jobs", nlohmann::json::array())) before.insert(j.value("name", ""));
    for (const Job& j : jobs) now.insert(j.name);
    std::vector<std::string> other;
    std::set_difference(before.begin(), before.end(), now.begin(), now.end(), std::back_inserter(other));
    if (!other.empty())
        throw InputError(fmt::format("{}: the summary of another batch (its job {} is not one of these); give --output-dir "
                                     "for this one", summaryPath, other.front()));
}

/// --resume: the jobs that finished in an earlier batch (not run again), by name.
std::map<std::string, nlohmann::json> finishedJobs(const std::string& summaryPath, bool resume) {
    std::map<std::string, nlohmann::json> previous;
    if (!resume || !std::filesystem::exists(summaryPath)) return previous;
    std::ifstream in(summaryPath);
    const nlohmann::json old = nlohmann::json::parse(in, nullptr, false);
    if (old.is_discarded()) throw InputError(fmt::format("{}: not a batch summary (JSON)", summaryPath));
    for (const auto& j : old.value("jobs", nlohmann::json::array()))
        if (j.value("outcome", "") == "ok") previous[j.value("name", "")] = j;
    return previous;
}

/// A job's process ended with `status`: its outcome, and its outputs or its error.
void recordOutcome(nlohmann::json& r, int status, double seconds, const std::filesystem::path& manifest) {
    r["seconds"] = seconds;
    if (WIFEXITED(status)) {
        r["exit_code"] = WEXITSTATUS(status);
        r["outcome"] = WEXITSTATUS(status) == 0 ? "ok" : WEXITSTATUS(status) > 128 ? "interrupted" : "failed";
    } else {
        r["signal"] = WTERMSIG(status);
        r["outcome"] = "crashed";
    }
    if (r["outcome"] == "ok") r["outputs"] = jobOutputs(manifest);
    else r["error"] = lastLine(r["log"].get<std::string>());
}

/// Nothing the batch writes itself (summary, logs, job lists) may replace
/// the jobs file or a scene.
void guardBatch(const BatchArgs& args, const std::vector<Job>& jobs, const std::string& summaryPath) {
    OutputGuard guard;
    guard.addInput(args.jobsFile);
    for (const Job& j : jobs) guard.addInput(j.scene);
    guard.check(summaryPath, "--summary");
    for (const Job& j : jobs) {
        guard.check(std::filesystem::path(args.outputDir) / (j.name + ".log"), "job log");
        guard.check(outputsFile(args, j), "job outputs list");
    }
}

/// A batch in progress: its jobs, their results so far (the summary), the
/// renders running.
class BatchRun {
public:
    BatchRun(const BatchArgs& args, const std::vector<Job>& jobs, std::string summaryPath,
             std::map<std::string, nlohmann::json> previous)
        : args_(args), jobs_(jobs), outDir_(args.outputDir), summaryPath_(std::move(summaryPath)), previous_(std::move(previous)),
          results_(jobs.size()), start_(std::chrono::steady_clock::now()) {
        summary_ = {{"version", std::string(version())}, {"jobs_file", args.jobsFile}, {"parallel", args.parallel},
                    {"jobs", nlohmann::json::array()}};
    }

    /// Runs the jobs, args.parallel at a time; a signal is forwarded to the
    /// running renders (they checkpoint and stop) and no job starts after it.
    void run() {
        StopSignal stop;
        while (done_ < jobs_.size()) {
            startJobs(stop);
            if (stop.pending() && !forwarded_) {  // the renders checkpoint and stop
                forwarded_ = stop.pending();
                for (const Running& r : running_) forwardStop(r.pid, forwarded_);
                if (!args_.quiet)
                    fmt::print(stderr, "accretion batch: {}: stopping {} running job(s)\n", StopSignal::name(forwarded_), running_.size());
            }
            if (running_.empty()) {
                if (stop.pending()) break;
                continue;
            }
            if (!reapOne()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
        for (std::size_t k = 0; k < jobs_.size(); ++k)
            if (results_[k].is_null()) results_[k] = {{"name", jobs_[k].name}, {"outcome", "not started"}};
        save();
    }

    int ok() const { return summary_["counts"].value("ok", 0); }
    int forwarded() const { return forwarded_; }

private:
    /// Jobs started up to the parallel limit (none after a stop request);
    /// those an earlier batch finished are skipped.
    void startJobs(const StopSignal& stop) {
        while (!stop.pending() && next_ < jobs_.size() && running_.size() < std::size_t(args_.parallel)) {
            const Job& j = jobs_[next_];
            if (auto it = previous_.find(j.name); it != previous_.end()) {
                results_[next_] = it->second;
                results_[next_]["skipped"] = "finished in an earlier batch";
                ++next_;
                ++done_;
                continue;
            }
            const std::filesystem::path log = outDir_ / (j.name + ".log");
            std::error_code ec;
            std::filesystem::create_directories(outDir_, ec);
            if (ec) throw InputError(fmt::format("{}: cannot create output directory: {}", outDir_.string(), ec.message()));
            const std::vector<std::string> argv = renderArgv(j, args_);
            results_[next_] = {{"name", j.name}, {"outcome", "running"}, {"log", log.string()},
                               {"command", fmt::format("accretion {}", fmt::join(argv.begin() + 1, argv.end(), " "))}};
            running_.push_back({next_, spawnSelf(argv, log), std::chrono::steady_clock::now()});
            if (!args_.quiet) fmt::print(stderr, "accretion batch: [{}/{}] {} started\n", next_ + 1, jobs_.size(), j.name);
            ++next_;
        }
    }

    /// One finished render's outcome recorded and the summary saved; false
    /// when none has finished.
    bool reapOne() {
        int status = 0;
        const pid_t pid = ::waitpid(-1, &status, WNOHANG);
        if (pid <= 0) return false;
        const auto it = std::find_if(running_.begin(), running_.end(), [&](const Running& r) { return r.pid == pid; });
        if (it == running_.end()) return true;
        nlohmann::json& r = results_[it->job];
        recordOutcome(r, status, std::chrono::duration<double>(std::chrono::steady_clock::now() - it->start).count(),
                      outputsFile(args_, jobs_[it->job]));
        if (!args_.quiet)
            fmt::print(stderr, "accretion batch: {} {} ({:.1f} s){}\n", r["name"].get<std::string>(), r["outcome"].get<std::string>(),
                       r["seconds"].get<double>(), r.contains("error") ? ": " + r["error"].get<std::string>() : "");
        running_.erase(it);
        ++done_;
        save();
        return true;
    }

    void save() {
        summary_["jobs"] = nlohmann::json::array();
        std::map<std::string, int> counts;
        for (const auto& r : results_)
            if (!r.is_null()) {
                summary_["jobs"].push_back(r);
                ++counts[r.value("outcome", "")];
            }
        summary_["counts"] = counts;
        summary_["total_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        writeJson(summaryPath_, summary_);
    }

    const BatchArgs& args_;
    const std::vector<Job>& jobs_;
    std::filesystem::path outDir_;
    std::string summaryPath_;
    std::map<std::string, nlohmann::json> previous_;
    nlohmann::json summary_;
    std::vector<nlohmann::json> results_;
    std::chrono::steady_clock::time_point start_;
    std::vector<Running> running_;
    std::size_t next_ = 0, done_ = 0;
    int forwarded_ = 0;
};

void runBatch(BatchArgs args) {
    const std::vector<Job> jobs = batchJobs(args);
    const std::filesystem::path outDir(args.outputDir);
    const std::string summaryPath = args.summary.empty() ? (outDir / "batch.json").string() : args.summary;
    guardBatch(args, jobs, summaryPath);
    refuseAnotherBatch(summaryPath, jobs);
    const OutputLock lock(std::filesystem::path(summaryPath).replace_extension(".lock"));  // one batch per summary
    BatchRun batch(args, jobs, summaryPath, finishedJobs(summaryPath, args.resume));
    batch.run();
    fmt::print("batch: {} of {} jobs ok; summary {}\n", batch.ok(), jobs.size(), summaryPath);
    if (batch.forwarded()) throw Interrupted{batch.forwarded()};
    if (batch.ok() != int(jobs.size())) throw BatchFailed{};
}

}  // namespace

void addBatchCommand(CLI::App& app) {
    auto args = std::make_shared<BatchArgs>();
    CLI::App* cmd = app.add_subcommand("batch", "Run many renders (a jobs file, or scenes x frames x seeds); one failing "
                                                "job does not stop the others; a summary JSON lists every outcome");
    cmd->add_option("jobs", args->jobsFile, "Jobs file (TOML): [batch] output_dir, parallel; [[job]] name, scene, frames, "
                                            "seed, estimator, spp, output, shard, define");
    cmd->add_option("--scene", args->scenes, "Scene file(s) (instead of a jobs file): one job per scene x frame x seed");
    cmd->add_option("--frames", args->frames, "Frames A:B: one job per frame");
    cmd->add_option("--seeds", args->seeds, "Seeds A:B: one job per seed");
    cmd->add_option("--estimator", args->estimator, "Estimator of every job (a job's own wins)");
    cmd->add_option("--spp", args->spp, "Samples per pixel of every job (a job's own wins)");
    cmd->add_option("-D,--define", args->defines, "Setting override for every job: -D section.key=value")->allow_extra_args(false);
    cmd->add_option("--output-dir", args->outputDir, "Where jobs write (<dir>/<job>/...), their logs and batch.json");
    cmd->add_option("--summary", args->summary, "Summary JSON path (default <output-dir>/batch.json)");
    cmd->add_option("-j,--parallel", args->parallel, "Jobs run at once (each render uses all cores; default 1)");
    cmd->add_option("--threads", args->threads, "Worker threads per job");
    cmd->add_flag("--resume", args->resume, "Skip jobs the summary lists as ok; others continue from their checkpoints");
    cmd->add_flag("-q,--quiet", args->quiet, "No progress on stderr");
    cmd->footer("Exit codes: 0 every job ok, 1 bad input (jobs file, command line), 4 some job failed, 128+N stopped by signal N.");
    cmd->callback([args, cmd] {
        args->outputDirGiven = cmd->get_option("--output-dir")->count() > 0;
        args->parallelGiven = cmd->get_option("--parallel")->count() > 0;
        runBatch(*args);
    });
}

}  // namespace accretion::cmd
