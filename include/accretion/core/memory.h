#pragma once
#include <cstdint>

namespace accretion {

/// Peak resident set of this process in bytes (VmHWM of /proc/self/status:
/// the high-water mark of its own address space, not inherited across
/// exec), or -1 where unavailable.
std::int64_t peakResidentBytes();

/// The machine's physical memory in bytes (sysconf), or 0 where unknown.
std::uint64_t physicalMemoryBytes();

}  // namespace accretion
