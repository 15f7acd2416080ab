// libFuzzer target: the particle readers (raw 32-byte records and binary
// PLY, told apart by the magic) must turn any bytes into particles or an
// InputError. The first byte picks the name (.ply or .bin: a .ply without
// the magic is refused), the rest is the file.
#include <cstddef>
#include <cstdint>
#include <string>

#include "accretion/core/error.h"
#include "accretion/particles/particle_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
    try {
        const accretion::Particles p = accretion::parseParticles((data[0] & 1) ? "f.ply" : "f.bin", bytes);
        for (std::size_t i = 0; i < p.size(); ++i)
            if (!(p.radius[i] > 0.0f) || !(p.opacity[i] >= 0.0f && p.opacity[i] <= 1.0f))
                __builtin_trap();  // the readers promise positive radii and opacities in [0,1]
    } catch (const accretion::InputError&) {
    }
    return 0;
}
