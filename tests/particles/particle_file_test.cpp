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
    CHECK_THAT(errorReading(dir / "noradius.ply"), Contains("no float property"));
}
