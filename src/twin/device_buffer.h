#pragma once
// One cudaMalloc'd buffer, owned (moves, never copies).
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "cuda_check.h"

namespace accretion::twin {

class DeviceBuffer {
public:
    DeviceBuffer() = default;
    explicit DeviceBuffer(std::size_t bytes) { resize(bytes); }
    ~DeviceBuffer() { release(); }
    DeviceBuffer(DeviceBuffer&& o) noexcept : ptr_(std::exchange(o.ptr_, nullptr)), bytes_(std::exchange(o.bytes_, 0)) {}
    DeviceBuffer& operator=(DeviceBuffer&& o) noexcept {
        if (this != &o) {
            release();
            ptr_ = std::exchange(o.ptr_, nullptr);
            bytes_ = std::exchange(o.bytes_, 0);
        }
        return *this;
    }
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;

    /// At least `bytes` (the old contents are not kept when it grows).
    void reserve(std::size_t bytes) {
        if (bytes > bytes_) resize(bytes);
    }
    void resize(std::size_t bytes) {
        release();
        if (bytes) CUDA_CHECK(cudaMalloc(&ptr_, bytes));
        bytes_ = bytes;
    }
    template <class T> void upload(const std::vector<T>& v) {
        reserve(v.size() * sizeof(T));
        if (!v.empty()) CUDA_CHECK(cudaMemcpy(ptr_, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice));
    }
    template <class T> std::vector<T> download(std::size_t count) const {
        std::vector<T> v(count);
        if (count) CUDA_CHECK(cudaMemcpy(v.data(), ptr_, count * sizeof(T), cudaMemcpyDeviceToHost));
        return v;
    }
    CUdeviceptr address() const { return reinterpret_cast<CUdeviceptr>(ptr_); }
    template <class T> T* as() const { return static_cast<T*>(ptr_); }
    std::size_t bytes() const { return bytes_; }

private:
    void release() {
        if (ptr_) cudaFree(ptr_);
        ptr_ = nullptr;
        bytes_ = 0;
    }
    void* ptr_ = nullptr;
    std::size_t bytes_ = 0;
};

}  // namespace accretion::twin
