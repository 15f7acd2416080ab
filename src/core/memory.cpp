#include "accretion/core/memory.h"

#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

namespace accretion {

std::int64_t peakResidentBytes() {
    std::ifstream in("/proc/self/status");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("VmHWM:", 0) != 0) continue;
        std::istringstream ss(line.substr(6));
        std::int64_t kb = -1;
        ss >> kb;
        return kb < 0 ? -1 : kb * 1024;
    }
    return -1;
}

std::uint64_t physicalMemoryBytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? std::uint64_t(pages) * std::uint64_t(size) : 0;
}

}  // namespace accretion
