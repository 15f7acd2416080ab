#include "accretion/core/error.h"

#include <cstdio>
#include <cstdlib>


namespace accretion {

void failCheck(const char* expr, const char* file, int line) {
    throw InternalError(fmt::format("internal check failed: {} at {}:{}", expr, file, line));
}

}  // namespace accretion
