#pragma once
// Errors of the CUDA runtime (cuda_error.h) and of OptiX as exceptions naming the call.
#include <string>

#include <optix.h>

#include "cuda_error.h"

namespace accretion::twin {

inline void optixCheck(OptixResult r, const char* call, const char* file, int line) {
    if (r != OPTIX_SUCCESS)
        throw GpuError(std::string(call) + ": " + optixGetErrorName(r) + " (" + file + ":" + std::to_string(line) + ")");
}

}  // namespace accretion::twin

#define OPTIX_CHECK(call) ::accretion::twin::optixCheck((call), #call, __FILE__, __LINE__)
