#pragma once
// Errors of the CUDA runtime and of OptiX as exceptions naming the call.
#include <stdexcept>
#include <string>

#include <cuda_runtime.h>
#include <optix.h>

namespace accretion::twin {

struct GpuError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

inline void cudaCheck(cudaError_t e, const char* call, const char* file, int line) {
    if (e != cudaSuccess)
        throw GpuError(std::string(call) + ": " + cudaGetErrorString(e) + " (" + file + ":" + std::to_string(line) + ")");
}
inline void optixCheck(OptixResult r, const char* call, const char* file, int line) {
    if (r != OPTIX_SUCCESS)
        throw GpuError(std::string(call) + ": " + optixGetErrorName(r) + " (" + file + ":" + std::to_string(line) + ")");
}

}  // namespace accretion::twin

#define CUDA_CHECK(call) ::accretion::twin::cudaCheck((call), #call, __FILE__, __LINE__)
#define OPTIX_CHECK(call) ::accretion::twin::optixCheck((call), #call, __FILE__, __LINE__)
