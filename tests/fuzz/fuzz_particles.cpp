// libFuzzer target: the particle readers (raw 32-byte records and binary
// PLY) must turn any file into particles or an InputError. The first byte
// picks the format; the rest is the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "accretion/core/error.h"
#include "accretion/particles/particle_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const std::string base = "/dev/shm/accretion_fuzz_" + std::to_string(getpid());
    const std::string file = base + ((data[0] & 1) ? ".ply" : ".bin");
    {
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    }
    try {
        const accretion::Particles p = accretion::readParticles(file);
        for (std::size_t i = 0; i < p.size(); ++i)
            if (!(p.radius[i] > 0.0f)) __builtin_trap();  // the readers promise positive radii
    } catch (const accretion::InputError&) {
    }
    return 0;
}
