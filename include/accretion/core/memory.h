#pragma once
#include <cstdint>

namespace accretion {

/// Peak resident set of this process in bytes (VmHWM of /proc/self/status:
/// the high-water mark of its own address space, not inherited across
/// exec), or -1 where unavailable.
std::int64_t peakResidentBytes();

}  // namespace accretion
