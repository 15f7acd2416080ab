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
    return std::string(ACCRETION_BINARY) + " render " + ACCRETION_SOURCE_DIR +
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
