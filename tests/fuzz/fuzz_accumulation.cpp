// libFuzzer target: the accumulation reader (checkpoints and shard sums).
// The input is a file without its trailing checksum, which the target
// appends, so that mutations reach the header and array parsing behind it;
// the reader must return consistent arrays or throw an InputError.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>

#include "accretion/core/error.h"
#include "accretion/io/accumulation_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    std::string bytes(reinterpret_cast<const char*>(data), size);
    const std::uint64_t sum = accretion::fnv1a64(bytes);
    bytes.append(reinterpret_cast<const char*>(&sum), 8);
    try {
        const accretion::AccumulationFile f = accretion::parseAccumulationFile(bytes, "f.checkpoint");
        const std::size_t px = f.acc.pixels();
        if (f.acc.sum.size() != px || f.acc.sumSq.size() != px || f.acc.n.size() != px || f.acc.done.size() != px ||
            f.acc.rejected.size() != px)
            __builtin_trap();
    } catch (const accretion::InputError&) {
    }
    return 0;
}
