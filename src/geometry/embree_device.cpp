#include "accretion/geometry/embree_device.h"

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

EmbreeDevice::EmbreeDevice(int threads) {
    const std::string config = threads > 0 ? fmt::format("threads={}", threads) : std::string();
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw InternalError(fmt::format("Embree: cannot create device (error {})", int(rtcGetDeviceError(nullptr))));
    rtcSetDeviceErrorFunction(device_, &EmbreeDevice::onError, this);
    rtcSetDeviceMemoryMonitorFunction(device_, &EmbreeDevice::onMemory, this);
}

EmbreeDevice::~EmbreeDevice() { rtcReleaseDevice(device_); }

void EmbreeDevice::onError(void* self, RTCError code, const char* message) {
    auto* d = static_cast<EmbreeDevice*>(self);
    if (!d->errorLock_.test_and_set()) d->firstError_ = fmt::format("Embree error {}: {}", int(code), message ? message : "");
    d->failed_ = true;
}

bool EmbreeDevice::onMemory(void* self, ssize_t bytes, bool) {
    static_cast<EmbreeDevice*>(self)->bytes_.fetch_add(bytes, std::memory_order_relaxed);
    return true;
}

void EmbreeDevice::check(const char* what) const {
    if (failed_) throw InternalError(fmt::format("{}: {}", what, firstError_));
}

}  // namespace accretion
