#pragma once
#include <atomic>
#include <cstdint>
#include <string>

#include <embree3/rtcore.h>

namespace accretion {

/// Owns the Embree device: one error callback (errors become exceptions at
/// the next check) and a memory monitor that measures Embree's bytes.
class EmbreeDevice {
public:
    explicit EmbreeDevice(int threads = 0);
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    RTCDevice get() const { return device_; }
    /// Throw InternalError if Embree reported an error since the last check.
    void check(const char* what) const;
    /// Bytes Embree holds now (BVHs, buffers), from its memory monitor.
    std::int64_t bytesInUse() const { return bytes_.load(std::memory_order_relaxed); }

private:
    static void onError(void* self, RTCError code, const char* message);
    static bool onMemory(void* self, ssize_t bytes, bool post);

    RTCDevice device_ = nullptr;
    std::atomic<std::int64_t> bytes_{0};
    mutable std::atomic<bool> failed_{false};
    std::string firstError_;
    std::atomic_flag errorLock_ = ATOMIC_FLAG_INIT;
};

}  // namespace accretion
