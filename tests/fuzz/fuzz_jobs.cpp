// libFuzzer target: the batch jobs-file reader. Any text must give jobs with
// a scene and a valid name each, or an InputError naming the file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "accretion/core/error.h"
#include "../../src/cmd/jobs_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const accretion::cmd::JobsFile f = accretion::cmd::parseJobsFile(text, "jobs.toml");
        if (f.jobs.empty()) __builtin_trap();  // a file without jobs is refused
        for (const accretion::cmd::Job& j : f.jobs)
            if (j.scene.empty() || !accretion::cmd::badJobName(j.name).empty()) __builtin_trap();
    } catch (const accretion::InputError&) {
    }
    return 0;
}
