#pragma once
// GPU time per pass name from CUDA events around each pass on one stream
// (read after the stream is synchronised), in order of first use.
#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "cuda_check.h"

namespace accretion::twin {

class GpuTimer {
public:
    explicit GpuTimer(cudaStream_t stream) : stream_(stream) {}
    ~GpuTimer() { clear(); }
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    void begin(const std::string& pass) {
        cudaEvent_t a, b;
        CUDA_CHECK(cudaEventCreate(&a));
        CUDA_CHECK(cudaEventCreate(&b));
        CUDA_CHECK(cudaEventRecord(a, stream_));
        open_.push_back({pass, a, b});
    }
    void end() {
        CUDA_CHECK(cudaEventRecord(open_.back().stop, stream_));
        done_.push_back(open_.back());
        open_.pop_back();
    }
    /// Milliseconds per pass (summed over its spans); synchronises the stream.
    std::vector<std::pair<std::string, double>> read() {
        CUDA_CHECK(cudaStreamSynchronize(stream_));
        std::vector<std::pair<std::string, double>> out;
        for (const Span& s : done_) {
            float ms = 0.0f;
            CUDA_CHECK(cudaEventElapsedTime(&ms, s.start, s.stop));
            auto it = std::find_if(out.begin(), out.end(), [&](const auto& p) { return p.first == s.pass; });
            if (it == out.end()) out.emplace_back(s.pass, ms);
            else it->second += ms;
        }
        clear();
        return out;
    }

private:
    struct Span {
        std::string pass;
        cudaEvent_t start, stop;
    };
    void clear() {
        for (const Span& s : done_) {
            cudaEventDestroy(s.start);
            cudaEventDestroy(s.stop);
        }
        done_.clear();
    }
    cudaStream_t stream_;
    std::vector<Span> open_, done_;
};

/// begin .. end of a pass for a scope.
class GpuScope {
public:
    GpuScope(GpuTimer& t, const std::string& pass) : t_(t) { t_.begin(pass); }
    ~GpuScope() { t_.end(); }
    GpuScope(const GpuScope&) = delete;
    GpuScope& operator=(const GpuScope&) = delete;

private:
    GpuTimer& t_;
};

}  // namespace accretion::twin
