#include "accretion/scene/estimator_table.h"
#include "accretion/gpu/gpu_report.h"

#include <bit>
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "accretion/core/pass.h"
#include "accretion/counters/gpu_layouts.h"
#include "accretion/gpu/cost_model.h"

namespace accretion {
namespace {

WarpLayout warpLayout(const GpuSettings& gpu) { return {gpu.group_width, gpu.group_height, gpu.warp_size}; }

/// Pipeline TraceRay pays off with many any-hits per ray
/// (they run as a compact separate shader) or divergence SER can regroup;
/// inline RayQuery wins for simple occlusion queries with no any-hit, a
/// trivial miss and a small payload.
void adviseRayModel(PassReport& p) {
    if (p.rays == 0) {
        p.rayModel = std::string(1, '-');
        p.reason = "no rays";
        return;
    }
    const double anyHitsPerRay = p.perRay(p.anyHits);
    const double serGain = p.ser.predictedSpeedup;
    const double efficiency = p.ser.branchBefore.efficiency * 0.5 + p.ser.loopBefore.efficiency * 0.5;
    if (anyHitsPerRay > 4.0) {
        p.rayModel = "pipeline";
        p.reason = fmt::format("{:.1f} any-hits per ray: a separate any-hit shader keeps the caller's registers", anyHitsPerRay);
    } else if (serGain > 1.15) {
        p.rayModel = "pipeline";
        p.reason = fmt::format("SER regrouping predicts {:.2f}x (SIMT efficiency {:.0f}%)", serGain, 100.0 * efficiency);
    } else if (anyHitsPerRay < 0.5) {
        p.rayModel = "inline";
        p.reason = fmt::format("{:.2f} any-hits per ray, SER gain {:.2f}x: a simple query, no payload to marshal",
                               anyHitsPerRay, serGain);
    } else {
        p.rayModel = "inline";
        p.reason = fmt::format("{:.1f} any-hits per ray and SER gain {:.2f}x are too small for the pipeline's overhead",
                               anyHitsPerRay, serGain);
    }
}

PassReport summarise(const PassCounters& pc, const GpuSettings& gpu, const SerKey& key) {
    PassReport p;
    p.pass = pc.id();
    p.width = pc.width;
    p.height = pc.height;
    p.dispatches = pc.dispatches;
    p.build = pc.build;
    p.footprintBytes = double(pc.footprintBytes);
    p.itemSteps = pc.itemSteps;
    for (const ThreadCounters& t : pc.threads) {
        p.threads += t.active;
        p.hitThreads += t.hit;
        p.maxTrips = std::max(p.maxTrips, t.trips);
#define ACC_SUM(member, key, doc) p.member += t.member;
        ACC_THREAD_COUNTERS(ACC_SUM)
        ACC_RAY_COUNTERS(ACC_SUM)
#undef ACC_SUM
    }
    p.ser = serOf(pc, gpu, key);
    adviseRayModel(p);
    return p;
}

}  // namespace

SerReport serOf(const PassCounters& pass, const GpuSettings& gpu, const SerKey& key) {
    return serReport(pass, warpLayout(gpu), key, gpu.ser_window, gpu.ser_reorder_cost);
}

GpuReport makeGpuReport(const FrameCounters& counters, const Settings& settings,
                        std::size_t reservoirBytes) {
    const GpuSettings& gpu = settings.gpu;
    GpuReport r;
    r.layout = warpLayout(gpu);
    const SerKey key(gpu.ser_key, gpu.ser_hint_bits);
    r.serKey = key.label();
    r.serWindow = gpu.ser_window;
    for (const PassCounters& pc : counters.passes) {
        PassReport p = summarise(pc, gpu, key);
        r.passes.push_back(std::move(p));
        r.layouts.bytesPerFrame += r.passes.back().bytesRead + r.passes.back().bytesWritten;
    }

    const AccelCounters& accel = counters.accel;
    r.blas = blasMemory(accel.blasPrimitives, gpu, accel.embreeBytes);
    // Working sets: the BLAS and TLAS bytes for traced passes; the light records (and
    // alias entries with power candidates) for the resampling passes.
    const std::uint64_t lights = accel.particles;
    const LightSource source = settings.render.source;
    const RestirSettings& rs = settings.restir;
    const bool presampled = sourceInfo(source).presampled;
    const double lightBytes = double(lights) * (gpu_layout::kParticleRecord + (source == LightSource::power || presampled ? gpu_layout::kAliasEntry : 0u) +
                                                (source == LightSource::tree ? 2u * gpu_layout::kLightTreeNode : 0u)) +
                              // the tiles, and the grid's slots
                              (presampled ? double(rs.tile_count) * rs.tile_size * gpu_layout::kRisEntry : 0.0) +
                              (sourceInfo(source).regirGrid ? std::pow(double(rs.regir_cells), 3.0) * rs.regir_lights_per_cell * gpu_layout::kRisEntry : 0.0);
    // A ray descends the TLAS before it enters any BLAS: its depth over the instances.
    const std::uint32_t tlasDepth = accel.tlasInstances > 1 ? std::uint32_t(std::bit_width(accel.tlasInstances - 1)) : 0u;
    for (PassReport& p : r.passes) {
        p.tlasLevels = p.rays * tlasDepth;
        if (p.rays > 0) p.workingSetBytes = double(r.blas.gpuBytes) + double(accel.tlasInstances) * gpu_layout::kTlasInstanceBytes;
        else if (passInfo(p.pass.pass).readsLights) p.workingSetBytes = lightBytes;
    }

    const std::uint64_t pixels = std::uint64_t(settings.camera.width) * settings.camera.height;
    const bool reuse = estimatorInfo(settings.render.estimator).restirPasses();
    const double s = reuse ? settings.restir.resolution_scale : 1.0;
    const std::uint64_t lightingPixels = static_cast<std::uint64_t>(double(pixels) * s * s + 0.5);
    const bool temporal = reuse && settings.restir.temporal;
    r.layouts.reservoirBytes = static_cast<std::uint32_t>(reservoirBytes);
    r.layouts.gbufferTexelBytes = gpu_layout::kGBufferTexel;
    r.layouts.primaryPayloadBytes = gpu_layout::kPrimaryPayload;
    r.layouts.shadowPayloadBytes = gpu_layout::kShadowPayload;
    r.layouts.reservoirBufferBytes = reservoirBytes * lightingPixels * (temporal ? 2 : 1);
    r.layouts.gbufferBufferBytes = gpu_layout::kGBufferTexel * pixels * (temporal ? 2 : 1);

    r.omm = accel.omm;
    return r;
}

namespace {

nlohmann::json simtJson(const SimtStats& s) {
    return {{"efficiency", s.efficiency},   {"active_threads_per_step", s.activeThreadsPerStep},
            {"distinct_keys_per_warp", s.distinctKeysPerWarp}, {"warps", s.warps},
            {"lane_work", s.laneWork},      {"steps", s.steps}};
}

}  // namespace

nlohmann::json toJson(const PassReport& p) {
    nlohmann::json j = {{"pass", p.pass.label()},
                        {"width", p.width},
                        {"height", p.height},
                        {"threads", p.threads},
                        {"hit_threads", p.hitThreads},
                        {"dispatches", p.dispatches},
                        {"blas_builds", p.build.blasBuilds},
                        {"blas_refits", p.build.blasRefits},
                        {"build_launches", p.build.builds},
                        {"refit_launches", p.build.refits},
                        {"accel_elements", p.build.elements},
                        {"build_primitives", p.build.primitives},
                        {"custom_builds", p.build.customBuilds},
                        {"sphere_refits", p.build.sphereRefits},
                        {"tlas_instances", p.build.tlasInstances},
                        {"tlas_instances_32k", p.build.tlasInstancesMid},
                        {"warp_segment_boxes", p.ser.traversalBefore.steps},
                        {"warp_node_visits", p.ser.nodesBefore.steps},
                        {"warp_gathers", p.ser.gathersBefore.steps},
                        {"hit_warps", p.ser.hitsBefore.warps},
                        {"footprint_bytes", p.footprintBytes},
                        {"item_steps", p.itemSteps},
                        {"tlas_levels", p.tlasLevels},
                        {"working_set_bytes", p.workingSetBytes},
                        {"max_trips", p.maxTrips},
                        {"blas_entries_per_ray", p.perRay(p.blasEntries)},
                        {"any_hits_per_ray", p.perRay(p.anyHits)},
                        {"warp_steps", p.warpSteps()},
                        {"simt_efficiency", {{"branch", simtJson(p.ser.branchBefore)}, {"loop", simtJson(p.ser.loopBefore)}}},
                        {"ser",
                         {{"key", p.ser.key},
                          {"branch_after", simtJson(p.ser.branchAfter)},
                          {"loop_after", simtJson(p.ser.loopAfter)},
                          {"distinct_sort_keys_per_warp_before", p.ser.distinctSortKeysBefore},
                          {"distinct_sort_keys_per_warp_after", p.ser.distinctSortKeysAfter},
                          {"reorder_steps", p.ser.reorderSteps},
                          {"predicted_speedup", p.ser.predictedSpeedup}}},
                        {"ray_model", {{"recommendation", p.rayModel}, {"reason", p.reason}}}};
#define ACC_JSON(member, key, doc) j[key] = p.member;
    ACC_THREAD_COUNTERS(ACC_JSON)
    ACC_RAY_COUNTERS(ACC_JSON)
#undef ACC_JSON
    return j;
}

nlohmann::json toJson(const GpuReport& r) {
    nlohmann::json passes = nlohmann::json::array();
    for (const PassReport& p : r.passes) passes.push_back(toJson(p));
    return {{"warp_layout", {{"group_width", r.layout.groupWidth}, {"group_height", r.layout.groupHeight},
                             {"warp_size", r.layout.warpSize}}},
            {"ser_key", r.serKey},
            {"ser_window", r.serWindow},
            {"passes", passes},
            {"blas_memory", toJson(r.blas)},
            {"layouts",
             {{"reservoir_bytes", r.layouts.reservoirBytes},
              {"gbuffer_texel_bytes", r.layouts.gbufferTexelBytes},
              {"primary_payload_bytes", r.layouts.primaryPayloadBytes},
              {"shadow_payload_bytes", r.layouts.shadowPayloadBytes},
              {"reservoir_buffer_bytes", r.layouts.reservoirBufferBytes},
              {"gbuffer_buffer_bytes", r.layouts.gbufferBufferBytes},
              {"bytes_per_frame", r.layouts.bytesPerFrame},
              {"bandwidth_gb_s_at_60fps", double(r.layouts.bytesPerFrame) * 60.0 / 1e9}}},
            {"omm",
             {{"enabled", r.omm.enabled},
              {"level", r.omm.level},
              {"states", r.omm.fourState ? 4 : 2},
              {"opaque", r.omm.opaque},
              {"transparent", r.omm.transparent},
              {"unknown", r.omm.unknown},
              {"shared_bytes", r.omm.sharedBytes},
              {"per_triangle_bytes", r.omm.perTriangleBytes}}}};
}

std::vector<Heatmap> counterHeatmaps(const FrameCounters& counters, std::uint32_t width, std::uint32_t height) {
    const std::size_t pixels = std::size_t(width) * height;
    std::vector<Heatmap> maps{{"gpu.rays", std::vector<float>(pixels, 0.0f), "rays per pixel, all passes"},
                              {"gpu.blas_entries", std::vector<float>(pixels, 0.0f), "BLAS entries per pixel, all passes"},
                              {"gpu.any_hits", std::vector<float>(pixels, 0.0f), "any-hit calls per pixel, all passes"},
                              {"gpu.trips", std::vector<float>(pixels, 0.0f), "light-loop trips per pixel, all passes"},
                              {"gpu.bytes", std::vector<float>(pixels, 0.0f), "bytes read + written per pixel, all passes"}};
    for (const PassCounters& pc : counters.passes) {
        if (pc.pass == Pass::buildClusters || pc.width == 0 || pc.height == 0) continue;
        // A pass that traces also gets its own map: the BLAS entries of its rays.
        bool traces = false;
        for (const ThreadCounters& t : pc.threads) traces = traces || t.rays > 0;
        if (traces)
            maps.push_back({fmt::format("gpu.{}.blas_entries", passName(pc.pass)), std::vector<float>(pixels, 0.0f),
                            fmt::format("BLAS entries per pixel, {}", passName(pc.pass))});
        Heatmap* own = traces ? &maps.back() : nullptr;
        for (std::uint32_t y = 0; y < height; ++y)
            for (std::uint32_t x = 0; x < width; ++x) {
                const std::uint32_t lx = std::min(pc.width - 1, std::uint32_t(std::uint64_t(x) * pc.width / width));
                const std::uint32_t ly = std::min(pc.height - 1, std::uint32_t(std::uint64_t(y) * pc.height / height));
                const ThreadCounters& t = pc.threads[std::size_t(ly) * pc.width + lx];
                const std::size_t px = std::size_t(y) * width + x;
                // A texel shared by several image pixels: each gets its share.
                const float share = float(pc.width) * float(pc.height) / (float(width) * float(height));
                maps[0].values[px] += share * float(t.rays);
                maps[1].values[px] += share * float(t.blasEntries);
                maps[2].values[px] += share * float(t.anyHits);
                maps[3].values[px] += share * float(t.trips);
                maps[4].values[px] += share * float(t.bytesRead + t.bytesWritten);
                if (own) own->values[px] += share * float(t.blasEntries);
            }
    }
    return maps;
}

}  // namespace accretion
