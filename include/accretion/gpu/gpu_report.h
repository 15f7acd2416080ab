#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "accretion/gpu/gpu_memory.h"
#include "accretion/counters/thread_counters.h"
#include "accretion/gpu/warp_model.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// One pass's counters, summed, with its SIMT/SER statistics and the
/// inline-RayQuery vs pipeline-TraceRay advice (docs/MODEL.md section 6).
struct PassReport {
    PassRun pass;
    std::uint32_t width = 0, height = 0;
    std::uint64_t threads = 0, hitThreads = 0;
    // The sums over the pass's threads of ACC_THREAD_COUNTERS and
    // ACC_RAY_COUNTERS (counters/thread_counters.h).
#define ACC_PASS_SUM(member, key, doc) std::uint64_t member = 0;
    ACC_THREAD_COUNTERS(ACC_PASS_SUM)
    ACC_RAY_COUNTERS(ACC_PASS_SUM)
#undef ACC_PASS_SUM
    std::uint64_t tlasLevels = 0;                                ///< rays x the TLAS's depth (log2 of its instances)
    std::uint64_t dispatches = 1;                                ///< kernel dispatches (PassCounters)
    BuildCounters build;                                          ///< buildClusters: launches, elements, TLAS instances
    /// Bytes of what the pass reads at random: the acceleration structures
    /// (traced passes), the light records (restir's resampling passes), else
    /// 0. With more of it than a cache holds, its reads miss (the cost model's
    /// cold_work).
    double workingSetBytes = 0.0;
    /// Distinct bytes of the grids the pass reads at other threads' texels
    /// (PassCounters::footprintBytes).
    double footprintBytes = 0.0;
    /// Steps of its kernels over other items than its grid (PassCounters::itemSteps).
    std::uint64_t itemSteps = 0;
    std::uint32_t maxTrips = 0;
    SerReport ser;
    std::string rayModel;  ///< "inline", "pipeline", or "-" (no rays)
    std::string reason;

    std::uint64_t warpSteps() const { return ser.branchBefore.steps + ser.loopBefore.steps; }
    double perRay(std::uint64_t n) const { return rays ? double(n) / double(rays) : 0.0; }
};

/// Reservoir, G-buffer and payload layouts and the bandwidth they imply.
struct LayoutReport {
    std::uint32_t reservoirBytes = 0;      ///< per stored reservoir (0 without restir)
    std::uint32_t gbufferTexelBytes = 0;
    std::uint32_t primaryPayloadBytes = 0, shadowPayloadBytes = 0;
    std::uint64_t reservoirBufferBytes = 0;  ///< current + history
    std::uint64_t gbufferBufferBytes = 0;    ///< current (+ previous with temporal reuse)
    std::uint64_t bytesPerFrame = 0;         ///< read + written by every pass
};

/// The micromap as the report gives it: its counters.
using OmmReport = OmmCounters;

/// The GPU model of one frame (docs/MODEL.md section 6).
struct GpuReport {
    WarpLayout layout;
    std::string serKey;
    std::uint32_t serWindow = 0;
    std::vector<PassReport> passes;
    BlasMemory blas;
    LayoutReport layouts;
    OmmReport omm;
};

/// Summarise a frame's counters (counters.accel gives cluster sizes, Embree memory and the OMM).
GpuReport makeGpuReport(const FrameCounters& counters, const Settings& settings,
                        std::size_t reservoirBytes);

/// SIMT / SER of one pass under another key or window (the cost command's key sweep).
SerReport serOf(const PassCounters& pass, const GpuSettings& gpu, const SerKey& key);

nlohmann::json toJson(const PassReport& p);
nlohmann::json toJson(const GpuReport& r);

/// Per-pixel heatmaps at image resolution, summed over the pixel passes
/// (a reduced-resolution pass counts at its texel): gpu.rays,
/// gpu.blas_entries, gpu.any_hits, gpu.trips, gpu.bytes.
struct Heatmap {
    std::string name;
    std::vector<float> values;
    std::string unit;  ///< what a value counts, e.g. "shadow and primary rays per pixel, all passes"
};
std::vector<Heatmap> counterHeatmaps(const FrameCounters& counters, std::uint32_t width, std::uint32_t height);

}  // namespace accretion
