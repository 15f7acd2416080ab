// Every bad input of tests/bad_input/ ends with its exact error, exit status
// 1, and no output file; the valid ones render.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "support/test_scenes.h"

namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& file) {
    std::ifstream in(file);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    return s;
}

std::string lastLine(const std::string& text) {
    std::string t = text;
    while (!t.empty() && t.back() == '\n') t.pop_back();
    const auto nl = t.rfind('\n');
    return nl == std::string::npos ? t : t.substr(nl + 1);
}

}  // namespace

TEST_CASE("the bad-input corpus: exact errors, exit 1, nothing written", "[cli][bad_input]") {
    const fs::path corpus = fs::path(ACCRETION_SOURCE_DIR) / "tests" / "bad_input";
    const std::string bin = ACCRETION_BINARY;
    std::vector<fs::path> cases;
    for (const auto& e : fs::directory_iterator(corpus))
        if (e.path().extension() == ".expected") cases.push_back(e.path());
    std::sort(cases.begin(), cases.end());
    REQUIRE(cases.size() >= 45);
    int bad = 0, ok = 0;
    for (const fs::path& expectedFile : cases) {
        const std::string name = expectedFile.stem().string();
        const fs::path out = accretion::test::scratchDir("bad_input_" + name);
        const bool isArgs = fs::exists(corpus / (name + ".args"));
        std::string cmd = "cd '" + corpus.string() + "' && " + bin + " render " + (isArgs ? "ok.toml" : name + ".toml") +
                          " --quiet -o '" + (out / (name + ".{frame}.exr")).string() + "'";
        if (isArgs) cmd += " " + readText(corpus / (name + ".args"));
        const std::string expected = readText(expectedFile);
        // A valid scene is only parsed and rendered small (an empty scene means
        // the defaults: 10K particles with the exact estimator).
        if (expected == "OK") cmd += " --estimator uniform --spp 1 -D camera.width=32 -D camera.height=16";
        std::string output;
        // stderr only: stdout (the frame log of valid runs) is dropped.
        const int status = accretion::test::runCommand("{ " + cmd + " 2>&1 >/dev/null; }", output);
        INFO(name << ": " << cmd << "\n" << output);
        if (expected == "OK") {
            CHECK(status == 0);
            CHECK(fs::exists(out / (name + ".0000.exr")));
            ++ok;
            continue;
        }
        ++bad;
        CHECK(status == 1);
        CHECK(lastLine(output) == expected);
        // No output at all: no EXR, PNG, stats or settings file, no temporary.
        CHECK(fs::is_empty(out));
    }
    CHECK(bad >= 43);  // 43 bad inputs, 2 valid ones
    CHECK(ok >= 2);
}
