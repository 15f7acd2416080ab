#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>

#include "accretion/core/error.h"
#include "accretion/particles/disk_generator.h"
#include "accretion/particles/particle_file.h"
#include "support/test_scenes.h"

using namespace accretion;
using Catch::Matchers::Contains;

namespace {

void writeBytes(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

std::string record(float x, float y, float z, float r, float er, float eg, float eb, float a) {
    const float f[8] = {x, y, z, r, er, eg, eb, a};
    return std::string(reinterpret_cast<const char*>(f), 32);
}

std::string errorReading(const std::filesystem::path& p) {
    try {
        readParticles(p);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("raw and PLY particle files round-trip bit-exactly", "[particles][io]") {
    const auto dir = accretion::test::scratchDir("particle_roundtrip");
    ParticleSettings s;
    s.count = 1000;
    const Particles p = generateDisk(s, 2);
    for (auto [name, fmt] : {std::pair{"p.bin", ParticleFormat::raw}, std::pair{"p.ply", ParticleFormat::ply}}) {
        writeParticles(dir / name, p, fmt);
        const Particles q = readParticles(dir / name);
        REQUIRE(q.position == p.position);
        REQUIRE(q.radius == p.radius);
        REQUIRE(q.emission == p.emission);
        REQUIRE(q.opacity == p.opacity);
    }
    REQUIRE(std::filesystem::file_size(dir / "p.bin") == 32 * 1000);
}

TEST_CASE("the raw layout is the GPU's ParticleData record", "[particles][io]") {
    const auto dir = accretion::test::scratchDir("particle_layout");
    writeBytes(dir / "one.bin", record(1, 2, 3, 0.5f, 4, 5, 6, 0.25f));
    const Particles p = readParticles(dir / "one.bin");
    REQUIRE(p.size() == 1);
    REQUIRE(p.position[0] == Vec3(1, 2, 3));
    REQUIRE(p.radius[0] == 0.5f);
    REQUIRE(p.emission[0] == Vec3(4, 5, 6));
    REQUIRE(p.opacity[0] == 0.25f);
}

TEST_CASE("bad particle files are rejected naming file and record", "[particles][io][errors]") {
    const auto dir = accretion::test::scratchDir("particle_bad");
    const std::string good = record(0, 0, 0, 1, 1, 1, 1, 1);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();

    writeBytes(dir / "size.bin", good + good + good.substr(0, 20));
    CHECK_THAT(errorReading(dir / "size.bin"), Contains("size.bin") && Contains("multiple of 32") && Contains("record 2"));
    writeBytes(dir / "nan.bin", good + good + good + record(0, nan, 0, 1, 1, 1, 1, 1));
    CHECK_THAT(errorReading(dir / "nan.bin"), Contains("nan.bin") && Contains("record 3") && Contains("y is not finite"));
    writeBytes(dir / "inf.bin", good + record(0, 0, 0, 1, inf, 1, 1, 1));
    CHECK_THAT(errorReading(dir / "inf.bin"), Contains("record 1") && Contains("emission_r"));
    writeBytes(dir / "radius.bin", good + good + record(0, 0, 0, 0, 1, 1, 1, 1));
    CHECK_THAT(errorReading(dir / "radius.bin"), Contains("record 2") && Contains("radius must be > 0"));
    writeBytes(dir / "neg.bin", record(0, 0, 0, 1, 1, -1, 1, 1));
    CHECK_THAT(errorReading(dir / "neg.bin"), Contains("record 0") && Contains("emission_g must be >= 0"));
    writeBytes(dir / "empty.bin", "");
    CHECK_THAT(errorReading(dir / "empty.bin"), Contains("empty.bin") && Contains("no particles"));
    CHECK_THAT(errorReading(dir / "missing.bin"), Contains("missing.bin") && Contains("cannot open"));

    // Truncated PLY: header says 5 records, data holds 3.5.
    Particles p;
    for (int i = 0; i < 5; ++i) p.push(Vec3(float(i)), 1.0f, Vec3(1.0f));
    writeParticles(dir / "full.ply", p, ParticleFormat::ply);
    std::ifstream in(dir / "full.ply", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    writeBytes(dir / "trunc.ply", bytes.substr(0, bytes.size() - 48));
    CHECK_THAT(errorReading(dir / "trunc.ply"), Contains("trunc.ply") && Contains("truncated") && Contains("record 3"));
    writeBytes(dir / "ascii.ply", "ply\nformat ascii 1.0\nelement vertex 1\nend_header\n");
    CHECK_THAT(errorReading(dir / "ascii.ply"), Contains("ascii.ply:2") && Contains("binary_little_endian"));
    writeBytes(dir / "noradius.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nend_header\n");
    CHECK_THAT(errorReading(dir / "noradius.ply"), Contains("no property 'y'"));
}

namespace {

/// A binary PLY of `n` vertices: the header lines (joined with `eol`), then
/// the body as given.
std::string ply(const std::vector<std::string>& lines, const std::string& body, const std::string& eol = "\n") {
    std::string h;
    for (const std::string& l : lines) h += l + eol;
    return h + body;
}

template <class T> std::string bytesOf(T v) { return std::string(reinterpret_cast<const char*>(&v), sizeof v); }

const std::vector<std::string> kSeven = {"property float x", "property float y", "property float z", "property float radius",
                                         "property float emission_r", "property float emission_g", "property float emission_b"};

std::vector<std::string> header(std::size_t n, std::vector<std::string> extra, bool seven = true) {
    std::vector<std::string> h = {"ply", "format binary_little_endian 1.0", "element vertex " + std::to_string(n)};
    if (seven) h.insert(h.end(), kSeven.begin(), kSeven.end());
    h.insert(h.end(), extra.begin(), extra.end());
    h.push_back("end_header");
    return h;
}

std::string sevenFloats(float x) {
    std::string r;
    for (float f : {x, 0.0f, 0.0f, 0.5f, 1.0f, 2.0f, 3.0f}) r += bytesOf(f);
    return r;
}

}  // namespace

TEST_CASE("PLY headers are read line by line and exactly", "[particles][io][ply]") {
    const auto dir = accretion::test::scratchDir("particle_ply");
    SECTION("a uchar opacity is read as 0..255 = 0..1, a double as its float") {
        writeBytes(dir / "u8.ply", ply(header(2, {"property uchar opacity"}), sevenFloats(1) + "\x33" + sevenFloats(2) + "\xff"));
        const Particles p = readParticles(dir / "u8.ply");
        REQUIRE(p.size() == 2);
        CHECK(p.opacity[0] == 0x33 / 255.0f);
        CHECK(p.opacity[1] == 1.0f);
        CHECK(p.position[1].x == 2.0f);
        std::vector<std::string> h = header(1, {"property double opacity"});
        writeBytes(dir / "f64.ply", ply(h, sevenFloats(1) + bytesOf(0.25)));
        CHECK(readParticles(dir / "f64.ply").opacity[0] == 0.25f);
    }
    SECTION("CRLF headers, comments that mention end_header, and .PLY in capitals") {
        writeBytes(dir / "crlf.ply", ply(header(1, {}), sevenFloats(4), "\r\n"));
        CHECK(readParticles(dir / "crlf.ply").position[0].x == 4.0f);
        std::vector<std::string> h = header(1, {});
        h.insert(h.begin() + 2, "comment this is not the end_header");
        writeBytes(dir / "comment.ply", ply(h, sevenFloats(5)));
        CHECK(readParticles(dir / "comment.ply").position[0].x == 5.0f);
        writeBytes(dir / "CAPS.PLY", ply(header(1, {}), sevenFloats(6)));
        CHECK(readParticles(dir / "CAPS.PLY").position[0].x == 6.0f);
        // The magic decides, not the name: a PLY named .bin is a PLY.
        writeBytes(dir / "named.bin", ply(header(1, {}), sevenFloats(7)));
        CHECK(readParticles(dir / "named.bin").position[0].x == 7.0f);
    }
    SECTION("the body holds exactly the declared vertices") {
        writeBytes(dir / "more.ply", ply(header(1, {}), sevenFloats(1) + sevenFloats(2)));
        CHECK_THAT(errorReading(dir / "more.ply"), Contains("28 bytes after the 1 declared vertices"));
        writeBytes(dir / "huge.ply", ply(header(4000000000000000000ull, {}), sevenFloats(1)));
        CHECK_THAT(errorReading(dir / "huge.ply"), Contains("huge.ply:3") && Contains("cannot be a file"));
        writeBytes(dir / "short.ply", ply(header(3, {}), sevenFloats(1) + sevenFloats(2)));
        CHECK_THAT(errorReading(dir / "short.ply"), Contains("truncated") && Contains("record 2"));
        // Another element after the vertices counts in the body.
        writeBytes(dir / "face.ply", ply(header(1, {"element extra 2", "property short k"}), sevenFloats(1) + "abcd"));
        CHECK(readParticles(dir / "face.ply").size() == 1);
    }
    SECTION("unnamed, duplicate and unconverted properties name their line") {
        writeBytes(dir / "unnamed.ply", ply(header(1, {"property float"}), sevenFloats(1) + "abcd"));
        CHECK_THAT(errorReading(dir / "unnamed.ply"), Contains("unnamed.ply:11") && Contains("without a name"));
        writeBytes(dir / "dup.ply", ply(header(1, {"property float x"}), sevenFloats(1) + "abcd"));
        CHECK_THAT(errorReading(dir / "dup.ply"), Contains("dup.ply:11") && Contains("'x' declared twice (first at line 4)"));
        std::vector<std::string> h = header(1, {}, false);
        h.insert(h.begin() + 3, "property int x");
        writeBytes(dir / "int.ply", ply(h, "abcd"));
        CHECK_THAT(errorReading(dir / "int.ply"), Contains("int.ply:4") && Contains("'x' is int"));
        writeBytes(dir / "list.ply", ply(header(1, {"property list uchar int idx"}), sevenFloats(1)));
        CHECK_THAT(errorReading(dir / "list.ply"), Contains("list.ply:11") && Contains("list properties"));
        writeBytes(dir / "notply.ply", std::string(32, '\0'));
        CHECK_THAT(errorReading(dir / "notply.ply"), Contains("not a PLY file"));
        writeBytes(dir / "noend.ply", "ply\nformat binary_little_endian 1.0\ncomment x\n");
        CHECK_THAT(errorReading(dir / "noend.ply"), Contains("no 'end_header'"));
    }
    SECTION("inspectParticleFile agrees with the reader without reading the records") {
        writeBytes(dir / "i.ply", ply(header(2, {}), sevenFloats(1) + sevenFloats(2)));
        CHECK(inspectParticleFile(dir / "i.ply").count == 2);
        writeBytes(dir / "i.bin", record(0, 0, 0, 1, 1, 1, 1, 1) + record(0, 0, 0, 1, 1, 1, 1, 1) + record(0, 0, 0, 1, 1, 1, 1, 1));
        CHECK(inspectParticleFile(dir / "i.bin").count == 3);
        CHECK(inspectParticleFile(dir / "i.bin").format == ParticleFormat::raw);
    }
}
