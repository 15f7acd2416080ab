#pragma once
// Errors of the CUDA runtime as exceptions naming the call (no OptiX: the
// CUDA kernel files include this; cuda_check.h adds OptiX's).
#include <stdexcept>
#include <string>

#include <cuda_runtime.h>

namespace accretion::twin {

struct GpuError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

inline void cudaCheck(cudaError_t e, const char* call, const char* file, int line) {
    if (e != cudaSuccess)
        throw GpuError(std::string(call) + ": " + cudaGetErrorString(e) + " (" + file + ":" + std::to_string(line) + ")");
}

}  // namespace accretion::twin

#define CUDA_CHECK(call) ::accretion::twin::cudaCheck((call), #call, __FILE__, __LINE__)
