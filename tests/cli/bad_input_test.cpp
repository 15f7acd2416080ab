// Every bad input of tests/bad_input/ ends with its exact error, exit status
// 1, no output file, and every input untouched byte for byte; the valid
// ones render.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "support/test_scenes.h"

namespace fs = std::filesystem;

namespace {

std::string readBytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string readText(const fs::path& file) {
    std::string s = readBytes(file);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    return s;
}

std::string lastLine(const std::string& text) {
    std::string t = text;
    while (!t.empty() && t.back() == '\n') t.pop_back();
    const auto nl = t.rfind('\n');
    return nl == std::string::npos ? t : t.substr(nl + 1);
}

/// Everything under `dir`: each path with its kind and, for files, its bytes
/// (links as their targets, never followed).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
    std::map<std::string, std::string> s;
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        const std::string rel = fs::relative(e.path(), dir).string();
        if (e.is_symlink()) s[rel] = "link " + fs::read_symlink(e.path()).string();
        else if (e.is_directory()) s[rel] = "dir";
        else s[rel] = "file " + readBytes(e.path());
    }
    return s;
}

/// What changed between two snapshots, for the failure message.
std::string difference(const std::map<std::string, std::string>& before, const std::map<std::string, std::string>& after) {
    std::string d;
    for (const auto& [k, v] : after)
        if (!before.count(k)) d += "new: " + k + "\n";
        else if (before.at(k) != v) d += "changed: " + k + "\n";
    for (const auto& [k, v] : before)
        if (!after.count(k)) d += "removed: " + k + "\n";
    return d;
}

}  // namespace

TEST_CASE("the bad-input corpus: exact errors, exit 1, nothing written, inputs untouched", "[cli][bad_input][long]") {
    const fs::path corpus = fs::path(ACCRETION_SOURCE_DIR) / "tests" / "bad_input";
    const std::string bin = accretion::test::programPath();
    // The cases run in a copy (links kept as links): a defect that writes over
    // an input is caught by the snapshots and never reaches the repository.
    const fs::path work = accretion::test::scratchDir("bad_input_corpus");
    fs::copy(corpus, work, fs::copy_options::recursive | fs::copy_options::copy_symlinks);
    std::vector<fs::path> cases;
    for (const auto& e : fs::directory_iterator(work))
        if (e.path().extension() == ".expected") cases.push_back(e.path());
    std::sort(cases.begin(), cases.end());
    REQUIRE(cases.size() >= 105);
    int bad = 0, ok = 0;
    for (const fs::path& expectedFile : cases) {
        const std::string name = expectedFile.stem().string();
        const fs::path out = accretion::test::scratchDir("bad_input_" + name);
        std::string cmd = "cd '" + work.string() + "' && ";
        if (fs::exists(work / (name + ".cmd"))) {
            // A whole command line (any subcommand), run in the corpus.
            cmd += bin + " " + readText(work / (name + ".cmd"));
        } else {
            const bool isArgs = fs::exists(work / (name + ".args"));
            cmd += bin + " render " + (isArgs ? "ok.toml" : name + ".toml") + " --quiet -o '" +
                   (out / (name + ".{frame}.exr")).string() + "'";
            if (isArgs) cmd += " " + readText(work / (name + ".args"));
        }
        const std::string expected = readText(expectedFile);
        // A valid scene is only parsed and rendered small (an empty scene means
        // the defaults: 10K particles with the exact estimator).
        if (expected == "OK") cmd += " --estimator uniform --spp 1 -D camera.width=32 -D camera.height=16";
        const auto before = snapshot(work);
        std::string output;
        // stderr only: stdout (the frame log of valid runs) is dropped.
        const int status = accretion::test::runCommand("{ " + cmd + " 2>&1 >/dev/null; }", output);
        INFO(name << ": " << cmd << "\n" << output);
        // Inputs untouched, nothing new beside them, whatever the outcome.
        const std::string changed = difference(before, snapshot(work));
        INFO("in the corpus:\n" << changed);
        CHECK(changed.empty());
        if (expected == "OK") {
            CHECK(status == 0);
            CHECK(fs::exists(out / (name + ".0000.exr")));
            ++ok;
            continue;
        }
        ++bad;
        CHECK(status == 1);
        // "..." at the end: the message starts so (the rest names machine figures).
        if (expected.size() > 3 && expected.compare(expected.size() - 3, 3, "...") == 0)
            CHECK(lastLine(output).rfind(expected.substr(0, expected.size() - 3), 0) == 0);
        else
            CHECK(lastLine(output) == expected);
        // No output at all: no EXR, PNG, stats or settings file, lock, temporary.
        CHECK(fs::is_empty(out));
    }
    CHECK(bad >= 98);
    CHECK(ok >= 7);
}
