#pragma once
// GPU time per step from CUDA events around each step on one stream (read
// after the stream is synchronised), in order of first use. A step is a
// pass, or a named part of one (buildBlas of buildClusters): each scope
// says which pass it times, so the timings join the CPU's cost rows.
#include <algorithm>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "accretion/core/pass_timer.h"
#include "cuda_check.h"

namespace accretion::twin {

class GpuTimer {
public:
    explicit GpuTimer(cudaStream_t stream) : stream_(stream) {}
    ~GpuTimer() { clear(); }
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    /// Opens `step` of run `run` of `pass` (the run itself, labelled as
    /// PassRun labels it, when step is empty: "spatialResampling[2]").
    void begin(Pass pass, std::string_view step = {}, std::uint32_t run = 1) {
        const PassRun id{pass, run};
        const std::string name = step.empty() ? id.label() : std::string(step);
        passOf_.emplace(name, id);
        cudaEvent_t a, b;
        CUDA_CHECK(cudaEventCreate(&a));
        CUDA_CHECK(cudaEventCreate(&b));
        CUDA_CHECK(cudaEventRecord(a, stream_));
        open_.push_back({name, a, b});
    }
    void end() {
        CUDA_CHECK(cudaEventRecord(open_.back().stop, stream_));
        done_.push_back(open_.back());
        open_.pop_back();
    }
    /// The run of a pass a step belongs to (a step this timer has opened).
    PassRun passOf(const std::string& step) const { return passOf_.at(step); }
    /// Milliseconds per step (summed over its spans); synchronises the stream.
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
    std::map<std::string, PassRun> passOf_;
};

/// begin .. end of a pass, or of a step of one, or of its run `run`, for a scope.
class GpuScope {
public:
    GpuScope(GpuTimer& t, Pass pass, std::string_view step = {}, std::uint32_t run = 1) : t_(t) { t_.begin(pass, step, run); }
    ~GpuScope() { t_.end(); }
    GpuScope(const GpuScope&) = delete;
    GpuScope& operator=(const GpuScope&) = delete;

private:
    GpuTimer& t_;
};

}  // namespace accretion::twin
