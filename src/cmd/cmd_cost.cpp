// accretion cost: the GPU model of one frame (docs/MODEL.md section 6): every
// pass's counters, SIMT and SER, any-hits with opacity micromaps, BLAS
// memory, layouts, ray-model advice, the counting overhead, and the
// predicted time per pass; JSON + CSV (the counters calibrate reads).
#include <algorithm>
#include <filesystem>
#include <memory>

#include <fmt/core.h>
#include <tbb/global_control.h>

#include "accretion/analysis/experiment.h"
#include "accretion/geometry/camera_track.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "accretion/core/median.h"
#include "accretion/core/parse.h"
#include "accretion/core/version.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/gpu/cost_model.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/report_table.h"
#include "accretion/io/stats_writer.h"
#include "accretion/scene/estimator_table.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CostArgs : SceneArgs {
    std::string output;
    std::string config;
    std::uint32_t history = 8;
    std::uint32_t overhead = 3;
    std::string clusterSizes = "10,100,1000";
    std::string ommLevels = "2,4,6";
    std::vector<std::string> serKeys = {"hit", "hit,type", "hit,type,cluster", "hit,cluster", "hit,type,hint"};
    bool uncalibrated = false;
};

std::vector<std::uint32_t> parseList(const std::string& text, const char* option, std::uint32_t lo, std::uint32_t hi) {
    std::vector<std::uint32_t> out;
    if (text.empty()) return out;
    for (const std::string& part : splitList(text, ',')) {
        const std::optional<std::uint64_t> v = parseUnsigned(part, hi);
        if (!v || *v < lo)
            throw InputError(fmt::format("command line {} {}: expected integers in [{}, {}] separated by commas", option, text, lo, hi));
        out.push_back(static_cast<std::uint32_t>(*v));
    }
    return out;
}

/// One rendered frame with its history (restir), counters per the settings.
struct CountedFrame {
    FrameImage image;
    FrameStats stats;
    GpuReport report;
};

CountedFrame renderCounted(const Settings& s, const ParticleSource& source, std::uint32_t frame, std::uint32_t history) {
    ExperimentRender r = renderForExperiment(s, source, frame, history);  // restir's history frames first
    CountedFrame out{std::move(r.image), std::move(r.stats), {}};
    if (s.gpu.counters) out.report = makeGpuReport(out.image.counters, s, out.stats.reservoirBytes);
    return out;
}

/// What the sections of a cost report read.
struct CostRun {
    const CostArgs& args;
    const Settings& settings;
    const ParticleSource& source;
    std::uint32_t frame;
    std::vector<std::uint32_t> clusterSizes, ommLevels;
    std::vector<SerKey> serKeys;
    void log(const std::string& msg) const {
        if (!args.quiet) fmt::print(stderr, "cost: {}\n", msg);
    }
};

/// Per-pass counters, SIMT, SER and predicted time: the console table and
/// the CSV calibrate reads (config, pass, features, predicted_ms).
Table passTable(const GpuReport& r, const CostCoefficients& coef, const std::string& config, double& totalMs) {
    const char* msTitle = coef.calibrated ? "pred. ms" : "uncal. ms";
    std::vector<Column> columns{{"config", "", 0, "{}", "{}", false}, {"pass", "pass", -20}, {"", "threads", 9},
                                {"", "trips", 11}, {"", "rays", 10}, {"", "BLAS/ray", 8, "{:.2f}"}, {"", "AH/ray", 8, "{:.2f}"},
                                {"", "proc/ray", 8, "{:.2f}"}, {"", "MB read", 9, "{:.1f}"}, {"", "MB write", 9, "{:.1f}"},
                                {"", "SIMTbr", 7, "{:>6.1f}%"}, {"", "SIMTlp", 7, "{:>6.1f}%"}, {"", "SER", 6, "{:>5.2f}x"},
                                {"", "model", 9}};
    for (std::string_view f : kCostFeatures) columns.push_back({std::string(f), "", 0, "{}", "{}", false});
    columns.push_back({"working_set_bytes", "", 0, "{}", "{}", false});
    columns.push_back({coef.calibrated ? "predicted_ms" : "uncalibrated_ms", msTitle, 9, "{:.3f}", "{:.6g}"});
    Table t(columns);
    totalMs = 0.0;
    for (const PassReport& p : r.passes) {
        const CostFeatures f = costFeatures(p, coef.cacheBytes);
        const double ms = coef.predictMs(p.pass.pass, f);
        totalMs += ms;
        std::vector<Cell> row{config, p.pass.label(), p.threads, p.trips, p.rays, p.perRay(p.blasEntries), p.perRay(p.anyHits),
                              p.perRay(p.proceeds), 1e-6 * double(p.bytesRead), 1e-6 * double(p.bytesWritten),
                              100.0 * p.ser.branchBefore.efficiency, 100.0 * p.ser.loopBefore.efficiency,
                              p.ser.predictedSpeedup, p.rayModel};
        for (double v : f) row.push_back(v);
        row.push_back(p.workingSetBytes);
        row.push_back(ms);
        t.add(row);
    }
    return t;
}

/// SER key sweep on every pass with hits: efficiency before / after per key, and the best key.
nlohmann::json reportSerSweep(const CostRun& run, const CountedFrame& main) {
    const Settings& settings = run.settings;
    nlohmann::json serSweep = nlohmann::json::array();
    fmt::print("\nSER (window {} threads, reorder cost {} lane-steps per thread): branch SIMT efficiency before -> after, "
               "distinct keys per warp, predicted speed-up\n", settings.gpu.ser_window, settings.gpu.ser_reorder_cost);
    for (const PassCounters& pc : main.image.counters.passes) {
        if (pc.pass == Pass::buildClusters) continue;
        std::string best;
        double bestGain = 0.0;
        for (const SerKey& k : run.serKeys) {
            const SerReport s = serOf(pc, settings.gpu, k);
            fmt::print("  {:<20} {:<26} {:5.1f}% -> {:5.1f}%  keys {:5.2f} -> {:5.2f}  loop {:5.1f}% -> {:5.1f}%  {:5.2f}x\n",
                       passName(pc.pass), s.key, 100.0 * s.branchBefore.efficiency, 100.0 * s.branchAfter.efficiency,
                       s.distinctSortKeysBefore, s.distinctSortKeysAfter, 100.0 * s.loopBefore.efficiency,
                       100.0 * s.loopAfter.efficiency, s.predictedSpeedup);
            serSweep.push_back({{"pass", passName(pc.pass)},
                                {"key", s.key},
                                {"branch_efficiency_before", s.branchBefore.efficiency},
                                {"branch_efficiency_after", s.branchAfter.efficiency},
                                {"loop_efficiency_before", s.loopBefore.efficiency},
                                {"loop_efficiency_after", s.loopAfter.efficiency},
                                {"distinct_keys_per_warp_before", s.distinctSortKeysBefore},
                                {"distinct_keys_per_warp_after", s.distinctSortKeysAfter},
                                {"predicted_speedup", s.predictedSpeedup}});
            if (s.predictedSpeedup > bestGain) {
                bestGain = s.predictedSpeedup;
                best = s.key;
            }
        }
        fmt::print("  {:<20} best key: {} ({:.2f}x)\n", passName(pc.pass), best, bestGain);
    }

    return serSweep;
}

/// Any-hit and opacity micromaps: alpha testing against OMM levels (4-state: same image; 2-state: its error).
nlohmann::json reportOmm(const CostRun& run, const CountedFrame& main) {
    const Settings& settings = run.settings;
    const CostArgs& a = run.args;
    const ParticleSource& source = run.source;
    const std::uint32_t frame = run.frame;
    nlohmann::json omm = nlohmann::json::array();
    if (settings.geometry.alpha == AlphaMode::disc && !run.ommLevels.empty()) {
        fmt::print("\nany-hit per ray (primary / shadow) and OMM memory (shared arrays vs one per triangle):\n");
        auto anyHits = [](const GpuReport& g, bool shadow) {
            std::uint64_t ah = 0, rays = 0;
            for (const PassReport& p : g.passes) {
                const bool isPrimary = p.pass.pass == Pass::traceGBuffer;
                if (p.rays == 0 || isPrimary == shadow) continue;
                ah += p.anyHits;
                rays += p.rays;
            }
            return rays ? double(ah) / double(rays) : 0.0;
        };
        Settings alpha = settings;
        alpha.gpu.omm = OmmMode::off;
        const CountedFrame base = settings.gpu.omm == OmmMode::off ? CountedFrame{} : renderCounted(alpha, source, frame, a.history);
        const CountedFrame& ref = settings.gpu.omm == OmmMode::off ? main : base;
        fmt::print("  {:<14} {:>8} {:>8}\n", "", "primary", "shadow");
        fmt::print("  {:<14} {:>8.3f} {:>8.3f}\n", "alpha test", anyHits(ref.report, false), anyHits(ref.report, true));
        omm.push_back({{"variant", "alpha"}, {"any_hits_per_primary_ray", anyHits(ref.report, false)},
                       {"any_hits_per_shadow_ray", anyHits(ref.report, true)}});
        for (const bool four : {true, false})
            for (std::uint32_t L : run.ommLevels) {
                Settings s = settings;
                s.gpu.omm = four ? OmmMode::four_state : OmmMode::two_state;
                s.gpu.omm_level = L;
                run.log(fmt::format("OMM {}-state level {}", four ? 4 : 2, L));
                const CountedFrame v = renderCounted(s, source, frame, a.history);
                // The whole image (with a stochastic estimator this includes its noise, as the
                // sample streams diverge) and the self-emission alone (coverage only, deterministic).
                const ErrorMetrics e = computeErrors(v.image.L, ref.image.L);
                const ErrorMetrics eLe = computeErrors(v.image.Le, ref.image.Le);
                std::size_t changed = 0;  // pixels whose visible particle differs from alpha testing
                for (std::size_t px = 0; px < v.image.particle.size(); ++px) changed += v.image.particle[px] != ref.image.particle[px];
                const double changedFraction = double(changed) / double(std::max<std::size_t>(1, v.image.particle.size()));
                const std::string name = fmt::format("omm {}-state L{}", four ? 4 : 2, L);
                fmt::print("  {:<14} {:>8.3f} {:>8.3f}  vs alpha: {:.2f}% of pixels see another particle, Le relMSE {:.3g} "
                           "MAPE {:.3g}, image relMSE {:.3g} MAPE {:.3g}; OMM bytes {} shared vs {}\n", name,
                           anyHits(v.report, false), anyHits(v.report, true), 100.0 * changedFraction, eLe.relMSE, eLe.MAPE,
                           e.relMSE, e.MAPE, v.report.omm.sharedBytes, v.report.omm.perTriangleBytes);
                omm.push_back({{"variant", name},
                               {"states", four ? 4 : 2},
                               {"level", L},
                               {"any_hits_per_primary_ray", anyHits(v.report, false)},
                               {"any_hits_per_shadow_ray", anyHits(v.report, true)},
                               {"image_relMSE_vs_alpha", e.relMSE},
                               {"image_MAPE_vs_alpha", e.MAPE},
                               {"Le_relMSE_vs_alpha", eLe.relMSE},
                               {"Le_MAPE_vs_alpha", eLe.MAPE},
                               {"image_identical", v.image.L == ref.image.L},
                               {"pixels_changed_fraction", changedFraction},
                               {"micro_triangles", {{"opaque", v.report.omm.opaque}, {"transparent", v.report.omm.transparent},
                                                    {"unknown", v.report.omm.unknown}}},
                               {"shared_bytes", v.report.omm.sharedBytes},
                               {"per_triangle_bytes", v.report.omm.perTriangleBytes}});
            }
    }

    return omm;
}

/// BLAS memory at other cluster sizes: the frame's particles, rebuilt.
nlohmann::json reportBlasMemory(const CostRun& run) {
    const Settings& settings = run.settings;
    const ParticleSource& source = run.source;
    const std::uint32_t frame = run.frame;
    nlohmann::json memory = nlohmann::json::array();
    if (!run.clusterSizes.empty()) {
        fmt::print("\nBLAS memory (GPU estimate {} B/triangle, {} B/node, width {}; Embree measured):\n",
                   settings.gpu.blas_bytes_per_triangle, settings.gpu.blas_bytes_per_node, settings.gpu.bvh_width);
        fmt::print("  {:>8} {:>8} {:>12} {:>14} {:>7} {:>12} {:>7} {:>12} {:>12}\n", "cluster", "BLASes", "GPU bytes",
                   "own alloc", "waste", "pooled", "waste", "compacted", "Embree");
        const Particles particles = source.frame(frame);
        const Camera camera = CameraTrack(settings.camera).at(frame);
        for (std::uint32_t size : run.clusterSizes) {
            GeometrySettings g = settings.geometry;
            g.cluster_size = size;
            g.build = BuildPolicy::rebuild;
            GpuSettings gpu = settings.gpu;
            gpu.counters = false;
            const EmbreeDevice device;
            ParticleBvh bvh(device, g, gpu);
            bvh.build(particles, camera);
            const AccelCounters accel = bvh.accelCounters();
            const BlasMemory m = blasMemory(accel.blasPrimitives, settings.gpu, accel.embreeBytes);
            fmt::print("  {:>8} {:>8} {:>12} {:>14} {:>6.1f}% {:>12} {:>6.1f}% {:>12} {:>12}\n", size, m.clusters, m.gpuBytes,
                       m.perBlasAllocBytes, 100.0 * m.perBlasWaste(), m.pooledBytes, 100.0 * m.pooledWaste(),
                       m.compactedPooledBytes, m.embreeBytes);
            nlohmann::json row = toJson(m);
            row["cluster_size"] = size;
            memory.push_back(std::move(row));
        }
    }
    return memory;
}

/// Reservoir, G-buffer and payload layouts, buffers and traffic.
void printLayouts(const GpuReport& r) {
    const LayoutReport& L = r.layouts;
    fmt::print("\nlayouts: reservoir {} B, G-buffer texel {} B, payloads {} B primary / {} B shadow; buffers: reservoirs {:.1f} MB, "
               "G-buffer {:.1f} MB; traffic {:.1f} MB per frame = {:.1f} GB/s at 60 fps\n",
               L.reservoirBytes, L.gbufferTexelBytes, L.primaryPayloadBytes, L.shadowPayloadBytes,
               1e-6 * double(L.reservoirBufferBytes), 1e-6 * double(L.gbufferBufferBytes), 1e-6 * double(L.bytesPerFrame),
               double(L.bytesPerFrame) * 60.0 / 1e9);

}

/// Counting overhead: the same frame with counters off and on, medians of N.
nlohmann::json measureOverhead(const CostRun& run) {
    const Settings& settings = run.settings;
    const CostArgs& a = run.args;
    const ParticleSource& source = run.source;
    const std::uint32_t frame = run.frame;
    nlohmann::json overhead;
    if (a.overhead > 0) {
        Settings off = settings;
        off.gpu.counters = false;
        std::vector<double> tOff, tOn;
        for (std::uint32_t k = 0; k < a.overhead; ++k) {
            run.log(fmt::format("counting overhead {}/{}", k + 1, a.overhead));
            tOff.push_back(renderCounted(off, source, frame, a.history).stats.seconds);
            tOn.push_back(renderCounted(settings, source, frame, a.history).stats.seconds);
        }
        const double mOff = median(tOff), mOn = median(tOn);
        fmt::print("counting overhead: frame {:.3f} s without counters, {:.3f} s with ({:.2f}x, median of {})\n", mOff, mOn,
                   mOn / mOff, a.overhead);
        overhead = {{"seconds_off", mOff}, {"seconds_on", mOn}, {"ratio", mOn / mOff}, {"runs", a.overhead}};
    }

    return overhead;
}

/// The counter heatmaps: one EXR of every map and a PNG of each.
void writeHeatmaps(const std::string& prefix, const CountedFrame& main, const Settings& settings, std::uint32_t frame) {
    std::vector<FloatChannel> maps;
    for (const Heatmap& h : main.image.heatmaps) {
        maps.push_back({h.name, h.values});
        writeHeatmapPng(prefix + "." + h.name + ".png", h.values, main.image.width, main.image.height, h.name + ": " + h.unit);
    }
    writeChannelsExr(prefix + ".heatmaps.exr", main.image.width, main.image.height, maps,
                     {{"version", std::string(version())}, {"scene", settings.scenePath}, {"frame", std::to_string(frame)}});
}

void runCost(const CostArgs& a) {
    const Settings settings =
        loadSceneArgs(a, {{"gpu.counters", "cost (counts every pass)", [](Settings& s) { s.gpu.counters = true; }}});
    requireWholeImage(settings, "cost");
    std::vector<SerKey> serKeys;
    for (const std::string& k : a.serKeys) serKeys.push_back(SerKey::parse(k, std::max(settings.gpu.ser_hint_bits, 4u), "--ser-keys " + k));
    const CostCoefficients coef = CostCoefficients::forSetting(a.uncalibrated ? "uncalibrated" : settings.gpu.coefficients);
    const auto threads = limitThreads(a.threads);
    const std::string prefix = a.output.empty() ? "out/" + settings.sceneName + ".cost" : std::filesystem::path(a.output).replace_extension().string();
    const std::string config = a.config.empty() ? settings.sceneName : a.config;
    OutputGuard guard = sceneInputs(settings);
    if (!settings.gpu.coefficients.empty() && settings.gpu.coefficients != "uncalibrated") guard.addInput(settings.gpu.coefficients);
    checkOutputs(guard, prefix, {".json", ".csv", ".heatmaps.exr"}, "-o");
    const ParticleSource source(settings);
    const CostRun run{a, settings, source, settings.render.frame_start, parseList(a.clusterSizes, "--cluster-sizes", 1, 10000000),
                      parseList(a.ommLevels, "--omm-levels", 0, 6), serKeys};
    const std::uint32_t frame = run.frame;

    run.log(fmt::format("frame {} of {} with counters ({} history frames)", frame, settings.scenePath,
                        estimatorInfo(settings.render.estimator).reuse ? std::min(frame, a.history) : 0));
    const CountedFrame main = renderCounted(settings, source, frame, a.history);
    const GpuReport& r = main.report;
    fmt::print("{}: frame {}, {}x{}, {} particles, {} clusters, estimator {}; warps {}x{} groups of {} lanes; cost: {}\n",
               settings.sceneName, frame, settings.camera.width, settings.camera.height, main.stats.particles,
               main.stats.bvh.clusters, enumName(settings.render.estimator), r.layout.groupWidth, r.layout.groupHeight,
               r.layout.warpSize, coef.source);
    double totalMs = 0.0;
    const Table passes = passTable(r, coef, config, totalMs);
    fmt::print("{}", passes.console());
    if (coef.calibrated)
        fmt::print("{:<20} predicted {:.3f} ms per frame ({})\n", "total", totalMs, coef.source);
    else
        fmt::print("{:<20} {:.3f} UNCALIBRATED ms per frame (an order-of-magnitude guess, not a measurement)\n", "total", totalMs);
    for (const PassReport& p : r.passes)
        if (p.rays > 0) fmt::print("  {}: {} ({})\n", p.pass.label(), p.rayModel, p.reason);

    nlohmann::json doc = toJson(r);
    for (std::size_t k = 0; k < r.passes.size(); ++k) doc["passes"][k]["predicted_ms"] =
        coef.predictMs(r.passes[k].pass.pass, costFeatures(r.passes[k], coef.cacheBytes));
    doc["ser_sweep"] = reportSerSweep(run, main);
    doc["any_hit_omm"] = reportOmm(run, main);
    doc["blas_memory_by_cluster_size"] = reportBlasMemory(run);
    printLayouts(r);
    doc["counting_overhead"] = measureOverhead(run);
    doc["version"] = std::string(version());
    doc["scene"] = settings.scenePath;
    doc["config"] = config;
    doc["frame"] = frame;
    doc["seed"] = settings.render.seed;
    doc["settings"] = settingsToToml(settings);
    doc["coefficients"] = coef.toJson();
    doc["predicted_ms"] = totalMs;
    doc["frame_seconds"] = main.stats.seconds;
    writeJson(prefix + ".json", doc);
    writeFileAtomic(prefix + ".csv", passes.csv());
    writeHeatmaps(prefix, main, settings, frame);
    fmt::print("cost: {}.json, {}.csv, {}.heatmaps.exr, {}.gpu.*.png\n", prefix, prefix, prefix, prefix);
}

}  // namespace

void addCostCommand(CLI::App& app) {
    auto args = std::make_shared<CostArgs>();
    CLI::App* cmd = app.add_subcommand("cost", "GPU model of a frame: counters, SIMT/SER, any-hit/OMM, memory, predicted time");
    addSceneOptions(cmd, *args, "Frame A (or A:B, the first is measured)");
    cmd->add_option("-o,--output", args->output, "Output JSON (the CSV, heatmap EXR and PNGs go beside it); default out/<scene>.cost.json");
    cmd->add_option("--history", args->history, "restir: frames rendered before the measured one");
    cmd->add_option("--config", args->config, "Configuration label of the CSV rows (default: the scene name)");
    cmd->add_option("--overhead", args->overhead, "Measure the counting overhead: renders with counters off and on, median of N (0: skip)");
    cmd->add_option("--cluster-sizes", args->clusterSizes, "BLAS memory table at these cluster sizes (empty: skip)");
    cmd->add_option("--omm-levels", args->ommLevels, "Disc alpha: OMM levels compared with alpha testing (empty: skip)");
    cmd->add_option("--ser-keys", args->serKeys, "SER sort keys compared (each comma-separated hit,type,cluster,hint)");
    cmd->add_flag("--uncalibrated", args->uncalibrated,
                  "Price with the uncalibrated order-of-magnitude defaults instead of the committed H100 calibration "
                  "(labelled as such; = -D gpu.coefficients=uncalibrated)");
    cmd->callback([args] { runCost(*args); });
}

}  // namespace accretion::cmd
