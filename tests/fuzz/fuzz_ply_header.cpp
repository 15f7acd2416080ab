// libFuzzer target: the PLY header alone. The input follows the magic line
// "ply\n" (header lines, end_header, then a body); the reader must read it
// or refuse it with an InputError, and what it reads must match the header
// it was given: the declared count, exactly.
#include <cstddef>
#include <cstdint>
#include <string>

#include "accretion/core/error.h"
#include "accretion/particles/particle_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string bytes = "ply\n" + std::string(reinterpret_cast<const char*>(data), size);
    try {
        const accretion::Particles p = accretion::parseParticles("f.ply", bytes);
        if (p.size() == 0 || p.size() > bytes.size()) __builtin_trap();  // one vertex is at least a byte
    } catch (const accretion::InputError&) {
    }
    return 0;
}
