// accretion_suite: the performance bars, each measured side by
// side with the limit that matters (a bare Embree loop over the same data),
// plus scaling curves, per-pass breakdowns and peak memory. Writes
// bench/results.json, bench/scaling_particles.csv, bench/scaling_resolution.csv
// and their PNG plots, and prints a table.
//   ./build/bench/accretion_suite [--quick] [--out bench] [--accretion build/accretion]
#include <sys/resource.h>
#include <sys/wait.h>
#include <spawn.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>

#include <CLI/CLI.hpp>
#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include "accretion/analysis/experiment.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/core/rng.h"
#include "accretion/core/version.h"
#include "accretion/geometry/particle_bvh.h"
#include "accretion/core/atomic_file.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/estimators.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/render/gbuffer.h"
#include "accretion/render/visibility.h"
#include "accretion/scene/scene_parser.h"

extern char** environ;

using namespace accretion;
using Clock = std::chrono::steady_clock;

namespace {

double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

/// Median wall time of `runs` calls.
double timeIt(int runs, const std::function<void()>& f) {
    std::vector<double> t;
    for (int k = 0; k < runs; ++k) {
        const auto t0 = Clock::now();
        f();
        t.push_back(seconds(t0));
    }
    return median(t);
}

/// Medians of several functions timed side by side: run k times each of
/// them in turn, so that a slow spell of the machine falls on all of them.
std::vector<double> timeInterleaved(int runs, const std::vector<std::function<void()>>& fs) {
    std::vector<std::vector<double>> t(fs.size());
    for (int k = 0; k < runs; ++k)
        for (std::size_t i = 0; i < fs.size(); ++i) {
            const auto t0 = Clock::now();
            fs[i]();
            t[i].push_back(seconds(t0));
        }
    std::vector<double> m;
    for (auto& ti : t) m.push_back(median(ti));
    return m;
}

void log(const std::string& s) { fmt::print(stderr, "suite: {}\n", s); }

nlohmann::json bar(double project, double limit, double limitRatio) {
    return {{"project_s", project}, {"limit_s", limit}, {"ratio", project / limit}, {"limit_ratio", limitRatio}};
}

/// The disk of scenes/disk_100k.toml with another particle count / resolution.
Settings diskScene(const std::string& sceneFile, std::uint32_t particles, std::uint32_t width, std::uint32_t height) {
    Settings s = loadScene(sceneFile);
    s.particles.count = particles;
    s.camera.width = width;
    s.camera.height = height;
    return s;
}

/// The same settings with another estimator.
Settings withEstimator(Settings s, EstimatorKind estimator) {
    s.render.estimator = estimator;
    return s;
}

// ---------------------------------------------------------------- BVH build

/// The limit: a bare loop that builds the same clusters (one quad BLAS each,
/// camera-facing corners) in parallel with TBB, then the TLAS of instances.
struct BareBuilder {
    RTCDevice device = rtcNewDevice(nullptr);
    std::vector<RTCScene> blas;
    RTCScene tlas = nullptr;
    ~BareBuilder() {
        release();
        rtcReleaseDevice(device);
    }
    void release() {
        for (RTCScene s : blas) rtcReleaseScene(s);
        blas.clear();
        if (tlas) rtcReleaseScene(tlas);
        tlas = nullptr;
    }
    void build(const Clusters& clusters, const Particles& p, const Camera& cam) {
        release();
        blas.assign(clusters.count(), nullptr);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, clusters.count(), 1), [&](const auto& r) {
            for (std::size_t c = r.begin(); c != r.end(); ++c) {
                const auto m = clusters.members(c);
                RTCScene scene = rtcNewScene(device);
                rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
                RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_QUAD);
                auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                     12, 4 * m.size()));
                auto* idx = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0,
                                                                                RTC_FORMAT_UINT4, 16, m.size()));
                for (std::size_t k = 0; k < m.size(); ++k) {
                    const Vec3 q = p.position[m[k]];
                    const float rad = p.radius[m[k]];
                    const Vec3 a = rad * cam.right, b = rad * cam.up;
                    const Vec3 corner[4] = {q - a - b, q + a - b, q + a + b, q - a + b};
                    for (int j = 0; j < 4; ++j)
                        for (int d = 0; d < 3; ++d) v[12 * k + 3 * j + d] = corner[j][d];
                    for (int j = 0; j < 4; ++j) idx[4 * k + j] = std::uint32_t(4 * k + j);
                }
                rtcCommitGeometry(g);
                rtcAttachGeometry(scene, g);
                rtcReleaseGeometry(g);
                rtcCommitScene(scene);
                blas[c] = scene;
            }
        });
        tlas = rtcNewScene(device);
        rtcSetSceneBuildQuality(tlas, RTC_BUILD_QUALITY_LOW);
        for (RTCScene s : blas) {
            RTCGeometry inst = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_INSTANCE);
            rtcSetGeometryInstancedScene(inst, s);
            rtcCommitGeometry(inst);
            rtcAttachGeometry(tlas, inst);
            rtcReleaseGeometry(inst);
        }
        rtcCommitScene(tlas);
    }
};

// ---------------------------------------------------------------- rays

struct RayBatch {
    std::vector<float> ox, oy, oz, dx, dy, dz, tfar;
    std::vector<Exclusion> exclude;
    std::size_t size() const { return ox.size(); }
    void push(const ShadowQuery& q) {
        ox.push_back(q.o.x), oy.push_back(q.o.y), oz.push_back(q.o.z);
        dx.push_back(q.d.x), dy.push_back(q.d.y), dz.push_back(q.d.z);
        tfar.push_back(q.tfar);
        exclude.push_back(q.exclude);
    }
};

/// The bare loops' segment: the exact query's [0, d] shortened by 1e-4 d at
/// both ends (the GPU's relative rule), so that an unfiltered query answers
/// the same question without excluding the receiver and the light.
constexpr float kBareMargin = 1e-4f;

/// The shadow rays the `uniform` estimator traces (same streams, same order
/// per pixel, exact visibility), rebuilt outside the pass.
RayBatch uniformShadowRays(const Particles& p, const GBuffer& gb, const Settings& s) {
    const LightArrays L(p, s.shading);
    const VisibilityOptions vis = VisibilityOptions::from(s.render);
    RayBatch rays;
    for (std::size_t px = 0; px < gb.texels.size(); ++px) {
        const GBufferTexel& g = gb.texels[px];
        if (!g.hit()) continue;
        const ShadingPoint sp = shadingPoint(g, p);
        Rng rng(px, 0, RngPass::lightSampling, s.render.seed, 1);
        for (std::uint32_t k = 0; k < s.render.samples; ++k) {
            // A stream per chunk of samples (render/accumulation.h).
            if (k > 0 && k % LightingPlan::kChunkSamples == 0)
                rng = Rng(px, 0, RngPass::lightSampling, s.render.seed, k / LightingPlan::kChunkSamples + 1);
            const LightSample x = sampleSource<false>(L, nullptr, rng);
            LightTerm t;
            if (!L.term<ShadingModel::lambert>(sp, x.i, t)) continue;
            const ShadowQuery q = shadowQuery<Primitive::billboard>(vis, sp, x.i, L.packed[x.i].position, L.packed[x.i].radius, t);
            if (q.tfar > q.tnear) rays.push(q);
        }
    }
    return rays;
}

/// rtcOccluded1 over every ray (unfiltered, shortened), in parallel; returns the occluded count.
std::size_t bareOccluded1(RTCScene scene, const RayBatch& r) {
    std::atomic<std::size_t> occluded{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r.size(), 1024), [&](const auto& range) {
        std::size_t n = 0;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            RTCRay ray{r.ox[i], r.oy[i], r.oz[i], kBareMargin * r.tfar[i], r.dx[i], r.dy[i], r.dz[i], 0.0f,
                       (1.0f - kBareMargin) * r.tfar[i], ~0u, 0, 0};
            rtcOccluded1(scene, &ctx, &ray);
            n += ray.tfar < 0.0f;
        }
        occluded += n;
    });
    return occluded;
}

/// The project's query alone (ParticleBvh::occluded, identity exclusion)
/// over the same exact segments.
std::size_t exactOccluded(const ParticleBvh& bvh, const RayBatch& r) {
    std::atomic<std::size_t> occluded{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r.size(), 1024), [&](const auto& range) {
        std::size_t n = 0;
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            n += bvh.occluded(Vec3(r.ox[i], r.oy[i], r.oz[i]), Vec3(r.dx[i], r.dy[i], r.dz[i]), 0.0f, r.tfar[i], r.exclude[i]);
        occluded += n;
    });
    return occluded;
}

/// rtcOccluded8 over groups of 8 consecutive rays (neighbouring pixels' samples).
std::size_t bareOccluded8(RTCScene scene, const RayBatch& r) {
    std::atomic<std::size_t> occluded{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (r.size() + 7) / 8, 128), [&](const auto& range) {
        std::size_t n = 0;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (std::size_t b = range.begin(); b != range.end(); ++b) {
            alignas(32) int valid[8];
            alignas(32) RTCRay8 ray;
            for (int k = 0; k < 8; ++k) {
                const std::size_t i = std::min(r.size() - 1, 8 * b + k);
                valid[k] = 8 * b + k < r.size() ? -1 : 0;
                ray.org_x[k] = r.ox[i], ray.org_y[k] = r.oy[i], ray.org_z[k] = r.oz[i];
                ray.dir_x[k] = r.dx[i], ray.dir_y[k] = r.dy[i], ray.dir_z[k] = r.dz[i];
                ray.tnear[k] = kBareMargin * r.tfar[i], ray.tfar[k] = (1.0f - kBareMargin) * r.tfar[i], ray.time[k] = 0.0f;
                ray.mask[k] = ~0u, ray.id[k] = 0, ray.flags[k] = 0;
            }
            rtcOccluded8(valid, scene, &ctx, &ray);
            for (int k = 0; k < 8; ++k) n += valid[k] && ray.tfar[k] < 0.0f;
        }
        occluded += n;
    });
    return occluded;
}

/// rtcIntersect1 / rtcIntersect8 (8x1 pixel rows) over the camera's pixel rays.
std::size_t bareIntersect(RTCScene scene, const Camera& cam, bool packets) {
    std::atomic<std::size_t> hits{0};
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, cam.height, 4), [&](const auto& rows) {
        std::size_t n = 0;
        RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        for (std::uint32_t y = rows.begin(); y != rows.end(); ++y) {
            if (!packets) {
                for (std::uint32_t x = 0; x < cam.width; ++x) {
                    const Vec3 d = cam.pixelDirection(x, y);
                    RTCRayHit rh{};
                    rh.ray = {cam.position.x, cam.position.y, cam.position.z, 0.0f, d.x, d.y, d.z, 0.0f,
                              std::numeric_limits<float>::infinity(), ~0u, 0, 0};
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(scene, &ctx, &rh);
                    n += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
                continue;
            }
            for (std::uint32_t x0 = 0; x0 < cam.width; x0 += 8) {
                alignas(32) int valid[8];
                alignas(32) RTCRayHit8 rh;
                for (int k = 0; k < 8; ++k) {
                    const std::uint32_t x = std::min(cam.width - 1, x0 + k);
                    valid[k] = x0 + k < cam.width ? -1 : 0;
                    const Vec3 d = cam.pixelDirection(x, y);
                    rh.ray.org_x[k] = cam.position.x, rh.ray.org_y[k] = cam.position.y, rh.ray.org_z[k] = cam.position.z;
                    rh.ray.dir_x[k] = d.x, rh.ray.dir_y[k] = d.y, rh.ray.dir_z[k] = d.z;
                    rh.ray.tnear[k] = 0.0f, rh.ray.tfar[k] = std::numeric_limits<float>::infinity();
                    rh.ray.time[k] = 0.0f, rh.ray.mask[k] = ~0u, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
                    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
                }
                rtcIntersect8(valid, scene, &ctx, &rh);
                for (int k = 0; k < 8; ++k) n += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
            }
        }
        hits += n;
    });
    return hits;
}

// ---------------------------------------------------------------- frames

struct FrameTiming {
    double frameSeconds = 0.0;
    std::map<Pass, double> passes;
    std::uint64_t shadowRays = 0, hitPixels = 0;
    /// A pass's seconds; the pass must have run.
    double seconds(Pass pass) const {
        const auto it = passes.find(pass);
        if (it == passes.end()) throw std::runtime_error(fmt::format("bench: no pass {} in the frame", passName(pass)));
        return it->second;
    }
};

/// Median frame time (and its passes) of `measured` frames after `history` frames.
FrameTiming timeFrames(const Settings& s, const ParticleSource& source, std::uint32_t first, std::uint32_t history,
                       std::uint32_t measured, bool rebuildStatic = false) {
    Settings run = s;
    run.render.frame_start = first;
    run.render.frames = history + measured;
    FrameRenderer renderer(run, source, RenderOptions{true, rebuildStatic});
    std::vector<FrameStats> stats;
    for (std::uint32_t f = 0; f < history + measured; ++f) {
        FrameStats fs;
        renderer.render(first + f, fs);
        if (f >= history) stats.push_back(std::move(fs));
    }
    std::sort(stats.begin(), stats.end(), [](const FrameStats& a, const FrameStats& b) { return a.seconds < b.seconds; });
    const FrameStats& m = stats[stats.size() / 2];
    FrameTiming t;
    t.frameSeconds = m.seconds;
    for (const auto& [pass, sec] : m.timer.all()) t.passes[pass] = sec;
    t.shadowRays = m.lighting.shadowRays;
    t.hitPixels = m.hitPixels;
    return t;
}

/// An unbiased estimator's cost of a reference image: frame seconds a + b S
/// at S samples per pixel and error v / S (relMSE against a reference, less
/// the reference's own noise), fitted on two sample counts.
struct ErrorCost {
    double a = 0.0, b = 0.0, v = 0.0;
    std::uint32_t maxSamples = 0;  ///< the largest sample count measured
    nlohmann::json points = nlohmann::json::array();
    double samplesTo(double relMSE) const { return v / relMSE; }
    double secondsTo(double relMSE) const { return a + b * samplesTo(relMSE); }
    nlohmann::json json(double target) const {
        return {{"fixed_s", a}, {"s_per_sample", b}, {"relMSE_times_samples", v}, {"seconds_to_target", secondsTo(target)},
                {"samples_to_target", samplesTo(target)}, {"largest_samples_measured", maxSamples},
                {"extrapolated", samplesTo(target) > 1.5 * maxSamples}, {"points", points}};
    }
};

/// Renders frame 0 of each setting `runs` times in turn (side by side) and
/// returns the images and median frame seconds.
std::vector<std::pair<FrameImage, double>> renderInterleaved(const std::vector<Settings>& settings, const ParticleSource& src,
                                                             int runs) {
    std::vector<std::pair<FrameImage, double>> out(settings.size());
    std::vector<std::vector<double>> t(settings.size());
    for (int k = 0; k < runs; ++k)
        for (std::size_t i = 0; i < settings.size(); ++i) {
            FrameRenderer renderer(settings[i], src, RenderOptions{true});
            FrameStats fs;
            out[i].first = renderer.render(0, fs);
            t[i].push_back(fs.seconds);
        }
    for (std::size_t i = 0; i < settings.size(); ++i) out[i].second = median(t[i]);
    return out;
}

/// relMSE of an image against a reference, less the reference's own noise.
double correctedRelMse(const FrameImage& img, const FrameImage& ref) {
    const ErrorMetrics e = computeErrors(img.lighting.Lr, ref.lighting.Lr, &ref.lighting.Lr_stderr);
    return e.relMSE - e.relMSEFloor;
}

/// The ErrorCost of each setting from renders at s1 and s2 samples per pixel, all side by side.
std::vector<ErrorCost> measureErrorCosts(const std::vector<Settings>& settings, const ParticleSource& src,
                                         const std::vector<std::vector<std::uint32_t>>& levels, const FrameImage& ref, int runs) {
    std::vector<Settings> all;
    for (std::size_t i = 0; i < settings.size(); ++i)
        for (const std::uint32_t S : levels[i]) {
            all.push_back(settings[i]);
            all.back().render.samples = S;
        }
    const auto images = renderInterleaved(all, src, runs);
    std::vector<ErrorCost> costs(settings.size());
    std::size_t at = 0;
    for (std::size_t i = 0; i < settings.size(); ++i) {
        // Least squares of t = a + b S over the levels; v = the median of relMSE x S.
        const std::size_t n = levels[i].size();
        double sS = 0.0, sT = 0.0, sSS = 0.0, sST = 0.0;
        std::vector<double> vs;
        ErrorCost& c = costs[i];
        for (std::size_t k = 0; k < n; ++k, ++at) {
            const auto& [img, t] = images[at];
            const double S = levels[i][k], e = correctedRelMse(img, ref);
            sS += S, sT += t, sSS += S * S, sST += S * t;
            vs.push_back(e * S);
            c.points.push_back({{"samples", levels[i][k]}, {"seconds", t}, {"relMSE", e}});
            c.maxSamples = std::max(c.maxSamples, levels[i][k]);
        }
        c.b = (double(n) * sST - sS * sT) / (double(n) * sSS - sS * sS);
        c.a = std::max(0.0, (sT - c.b * sS) / double(n));
        c.v = median(vs);
    }
    return costs;
}

/// Sample counts from `first`, x4 each, up to the first at or past the
/// count that reaches `target` by a two-level estimate (capped at `most`):
/// a fit that spans what it is used to predict.
std::vector<std::uint32_t> levelsTo(const Settings& s, const ParticleSource& src, const FrameImage& ref, double target,
                                    std::uint32_t first, std::uint32_t most) {
    const ErrorCost probe = measureErrorCosts({s}, src, {{first, 4 * first}}, ref, 1)[0];
    std::vector<std::uint32_t> out;
    for (std::uint32_t S = first; S <= most; S *= 4) {
        out.push_back(S);
        if (S >= probe.samplesTo(target)) break;
    }
    return out;
}

/// Runs a child process; true if it exits 0.
bool runChild(const std::vector<std::string>& argv) {
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid;
    if (posix_spawn(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return false;
    int status = 0;
    return waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

std::string machine() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown";
}

/// A long split render (k = 1024 near lights, 1024 spp, 128 when quick) of
/// frame `frame`: the reference where exact is unaffordable, with its
/// description for the figures.
struct SplitReference {
    FrameImage image;
    nlohmann::json json;
};
SplitReference renderSplitReference(const Settings& base, const ParticleSource& src, std::uint32_t frame, bool quick) {
    Settings ref = base;
    ref.render.estimator = EstimatorKind::split;
    ref.render.near_lights = 1024;
    ref.render.samples = quick ? 128 : 1024;
    ref.render.seed = 1000;
    ref.render.frame_start = frame;
    FrameRenderer renderer(ref, src, RenderOptions{true});
    FrameStats stats;
    SplitReference r{renderer.render(frame, stats), {}};
    r.json = {{"estimator", "split"}, {"near_lights", ref.render.near_lights}, {"samples", ref.render.samples},
              {"frame", frame}, {"seconds", stats.seconds},
              {"relMSE_floor", computeErrors(r.image.lighting.Lr, r.image.lighting.Lr, &r.image.lighting.Lr_stderr).relMSEFloor}};
    return r;
}

}  // namespace

/// What the sections of the suite share: the options, the 100K disk frame and the results.
struct Suite {
    bool quick = false;
    std::string outDir = "bench", binary = "build/accretion", micro = "build/bench/accretion_bench",
                scene = "scenes/disk_100k.toml";
    int cores = 1;
    Settings disk;
    ParticleSource diskSource;
    Particles p0, p1;
    Camera cam;
    EmbreeDevice device;
    double build100k = 0.0;  ///< the 100K rebuild, the 1M bar's limit
    nlohmann::json bars, figures;

    explicit Suite(const std::string& scenePath)
        : scene(scenePath), cores(tbb::info::default_concurrency()), disk(diskScene(scenePath, 100'000, 1280, 720)),
          diskSource(disk), p0(diskSource.frame(0)), p1(diskSource.frame(1)), cam(Camera::atFrame(disk.camera, 0)) {}
    Settings restirScene() const;  ///< the disk scene with restir
    // The sections, in the order main runs them.
    void benchBvhRebuild();
    void benchBvhRebuild1M();
    void benchRays();
    void benchRestirFrame();
    void benchTreeReference();
    void benchSplitReference();
    void benchRestirSources();
    void benchScaling();
    void benchMemory();
    void benchPlanSkips();
    void benchMicro();
};

Settings Suite::restirScene() const {
    Settings restir = disk;
    restir.render.estimator = EstimatorKind::restir;
    return restir;
}

/// BVH rebuild at 100K, clusters of ~100, fast build; refit and partial policies.
void Suite::benchBvhRebuild() {
    {
        log("BVH rebuild, 100K particles");
        ParticleBvh bvh(device, disk.geometry);
        int f = 0;
        bvh.build(p0, cam);
        build100k = timeIt(9, [&] { bvh.build(++f % 2 ? p1 : p0, cam); });
        BareBuilder bare;
        const Clusters clusters = bvh.clusters();
        bare.build(clusters, p0, cam);
        const double limit = timeIt(9, [&] { bare.build(clusters, ++f % 2 ? p1 : p0, cam); });
        bars["bvh_rebuild_100k"] = bar(build100k, limit, 1.3);
        const BvhStats& st = bvh.stats();
        figures["bvh_rebuild_100k_breakdown_s"] = {{"cluster", st.clusterSeconds}, {"blas", st.blasSeconds},
                                                   {"tlas", st.tlasSeconds}, {"clusters", st.clusters}};
        // Refit and partial rebuild against the moved fraction.
        nlohmann::json policies;
        Settings g = disk;
        g.geometry.build = BuildPolicy::refit;
        ParticleBvh refit(device, g.geometry);
        refit.build(p0, cam);
        policies["refit"] = timeIt(9, [&] { refit.build(++f % 2 ? p1 : p0, cam); });
        for (double fraction : {0.1, 0.3, 0.7, 1.0}) {
            g.geometry.build = BuildPolicy::partial;
            g.geometry.rebuild_fraction = fraction;
            ParticleBvh partial(device, g.geometry);
            partial.build(p0, cam);
            policies[fmt::format("partial_{}", fraction)] = timeIt(9, [&] { partial.build(++f % 2 ? p1 : p0, cam); });
        }
        policies["rebuild"] = build100k;
        figures["bvh_policies_100k_s"] = policies;
    }
}

/// BVH rebuild at 1M particles, against 10x the 100K build.
void Suite::benchBvhRebuild1M() {
    {
        log("BVH rebuild, 1M particles");
        const Settings big = diskScene(scene, 1'000'000, 1280, 720);
        const ParticleSource src(big);
        const Particles q0 = src.frame(0), q1 = src.frame(1);
        ParticleBvh bvh(device, big.geometry);
        int f = 0;
        bvh.build(q0, cam);
        const double t = timeIt(5, [&] { bvh.build(++f % 2 ? q1 : q0, cam); });
        bars["bvh_rebuild_1m_vs_100k"] = bar(t, build100k, 10.0);
    }
}

/// Rays: the real passes against bare Embree loops over the same rays and BVH.
void Suite::benchRays() {
    {
        log("primary and shadow rays, 100K particles at 1280x720");
        ParticleBvh bvh(device, disk.geometry);
        bvh.build(p0, cam);
        GBuffer gb;
        traceGBuffer(bvh, p0, cam, disk.shading.model, gb);
        const std::vector<double> tp = timeInterleaved(9, {[&] { traceGBuffer(bvh, p0, cam, disk.shading.model, gb); },
                                                           [&] { bareIntersect(bvh.scene(), cam, false); },
                                                           [&] { bareIntersect(bvh.scene(), cam, true); }});
        const double primary = tp[0], bare1 = tp[1], bare8 = tp[2];
        const double primaryLimit = std::min(bare1, bare8);
        bars["primary_rays"] = bar(primary, primaryLimit, 1.25);
        const double nPrimary = double(cam.width) * cam.height;
        figures["primary_rays_per_s_per_core"] = {{"project", nPrimary / primary / cores},
                                                  {"bare_rtcIntersect1", nPrimary / bare1 / cores},
                                                  {"bare_rtcIntersect8", nPrimary / bare8 / cores}};

        Settings u = disk;
        u.render.estimator = EstimatorKind::uniform;
        u.render.samples = 4;
        const RayBatch rays = uniformShadowRays(p0, gb, u);
        LightingImage out;
        std::uint64_t traced = 0, occludedPass = 0;
        // The limit: bare loops over a BVH of the same clusters without filter
        // callbacks (the project's BLAS exclude by identity in theirs).
        BareBuilder bare;
        bare.build(bvh.clusters(), p0, cam);
        std::size_t occ1 = 0, occ8 = 0, occExact = 0;
        const std::vector<double> ts = timeInterleaved(9, {[&] {
                                                               LightingInputs in{bvh, p0, gb, u.shading, u.render, 0, nullptr, nullptr};
                                                               const LightingCounters c = estimateLighting(in, out);
                                                               traced = c.shadowRays;
                                                               occludedPass = c.shadowOccluded;
                                                           },
                                                           [&] { occ1 = bareOccluded1(bare.tlas, rays); },
                                                           [&] { occ8 = bareOccluded8(bare.tlas, rays); },
                                                           [&] { occExact = exactOccluded(bvh, rays); }});
        const double shadow = ts[0], s1 = ts[1], s8 = ts[2], sx = ts[3];
        if (traced != rays.size() || occExact != occludedPass)
            log(fmt::format("warning: {} rays traced by the pass, {} rebuilt; occluded {} vs {}", traced, rays.size(),
                            occludedPass, occExact));
        bars["shadow_rays"] = bar(shadow, std::min(s1, s8), 1.25);
        const double n = double(rays.size());
        figures["shadow_rays_per_s_per_core"] = {{"project", n / shadow / cores},
                                                 {"bare_rtcOccluded1", n / s1 / cores},
                                                 {"bare_rtcOccluded8", n / s8 / cores},
                                                 {"exact_query_only", n / sx / cores},
                                                 {"rays", rays.size()},
                                                 {"occluded_fraction", double(occExact) / n},
                                                 {"occluded_fraction_bare_shortened", double(occ1) / n}};
    }
}

/// ReSTIR frame: per-pass breakdown and candidates per second per core.
void Suite::benchRestirFrame() {
    const Settings restir = restirScene();
    {
        log("restir frame, 100K particles at 1280x720");
        const FrameTiming t = timeFrames(restir, diskSource, 4, 4, 3);
        double lighting = 0.0;
        nlohmann::json passes;
        for (const auto& [pass, sec] : t.passes) passes[std::string(passName(pass))] = sec;
        for (const Pass pass : {Pass::generateCandidates, Pass::temporalResampling, Pass::spatialResampling})
            if (const auto it = t.passes.find(pass); it != t.passes.end()) lighting += it->second;
        const double candidates = double(t.hitPixels) * restir.render.candidates;
        figures["restir_frame_100k_720p"] = {
            {"seconds", t.frameSeconds},
            {"passes_s", passes},
            {"resampling_share", lighting / t.frameSeconds},
            {"candidates_per_s_per_core", candidates / t.seconds(Pass::generateCandidates) / cores},
            {"shadow_rays", t.shadowRays}};
    }
}

/// The tree reference to 1% per-pixel relative standard error on the same frame.
void Suite::benchTreeReference() {
    if (!quick) {
        log("tree to 1% relative standard error (minutes)");
        Settings tree = withEstimator(disk, EstimatorKind::tree);
        tree.render.samples = 64;
        tree.render.target_stderr = 0.01;
        tree.render.max_samples = 4096;
        const FrameTiming t = timeFrames(tree, diskSource, 8, 0, 1);
        figures["tree_to_1pct_100k_720p_s"] = t.frameSeconds;
    }
}

/// split against tree (disk_100k) and against exact (the quickstart) at
/// 320x180: the seconds each needs to reach relMSE 1e-3, from renders at
/// sample counts x4 apart up to the one that reaches it, side by side
/// (ErrorCost: t = a + b S fitted over them all), against a reference that
/// shares no sampling with them where one is affordable (exact, 10K) and a
/// long split render otherwise (its noise subtracted).
void Suite::benchSplitReference() {
    constexpr double kTarget = 1e-3;
    {
        log("split against tree to relMSE 1e-3, 100K particles at 320x180 (minutes)");
        Settings base = diskScene(scene, 100'000, 320, 180);
        const ParticleSource src(base);
        const SplitReference ref = renderSplitReference(base, src, 0, quick);
        const Settings tree = withEstimator(base, EstimatorKind::tree);
        Settings split = withEstimator(base, EstimatorKind::split);
        split.render.near_lights = 1024;  // the automatic k of a long render, fixed so that the cost is a + b S
        const std::uint32_t most = quick ? 128 : 4096;
        const auto c = measureErrorCosts({tree, split}, src,
                                         {levelsTo(tree, src, ref.image, kTarget, 8, most), levelsTo(split, src, ref.image, kTarget, 8, most)},
                                         ref.image, quick ? 1 : 3);
        const ErrorCost& t = c[0];
        const ErrorCost& sp = c[1];
        figures["split_vs_tree_100k_320x180"] = {
            {"reference", ref.json},
            {"near_lights", split.render.near_lights},
            {"tree", t.json(kTarget)},
            {"split", sp.json(kTarget)},
            {"tree_s_to_1e-2", t.secondsTo(1e-2)},
            {"split_s_to_1e-2", sp.secondsTo(1e-2)}};
        // Bar: split reaches 1e-3 at least 10x sooner than tree.
        bars["split_vs_tree_to_1e-3"] = bar(sp.secondsTo(kTarget), t.secondsTo(kTarget), 0.1);
    }
    {
        log("split against exact to relMSE 1e-3, quickstart (10K particles) at 320x180");
        Settings base = loadScene((std::filesystem::path(scene).parent_path() / "quickstart.toml").string());
        base.camera.width = 320;
        base.camera.height = 180;
        const ParticleSource src(base);
        const auto ex = renderInterleaved({withEstimator(base, EstimatorKind::exact)}, src, quick ? 1 : 3);
        Settings split = withEstimator(base, EstimatorKind::split);
        split.render.near_lights = 1024;
        const ErrorCost sp = measureErrorCosts({split}, src, {levelsTo(split, src, ex[0].first, kTarget, 8, quick ? 128 : 4096)},
                                               ex[0].first, quick ? 1 : 3)[0];
        figures["split_vs_exact_10k_320x180"] = {{"exact_s", ex[0].second}, {"split", sp.json(kTarget)},
                                                 {"split_s_to_1e-4", sp.secondsTo(1e-4)}};
        // Bar: where exact is cheaper than tree (below relMSE 3e-3 here), split is no slower than exact.
        bars["split_vs_exact_to_1e-3"] = bar(sp.secondsTo(kTarget), ex[0].second, 1.0);
    }
}

/// restir against uniform Monte Carlo at equal time on disk_100k at 320x180
/// (the bar: the best unbiased configuration at least 5x lower
/// error): frame 1 after one history frame, per seed the restir frame's
/// relMSE against uniform's at the same time (uniform's relMSE x seconds
/// is constant in its samples: relMSE_u t_u / t_r), the median over seeds of
/// their ratio. The configuration is the best unbiased one of docs/experiments.md's
/// restir table (scripts/restir_table.py); the reference is split at
/// k = 1024, 1024 spp (its noise subtracted).
void Suite::benchRestirSources() {
    log("restir (pairwise, light tree candidates) against uniform at equal time, 100K at 320x180");
    Settings base = diskScene(scene, 100'000, 320, 180);
    const ParticleSource src(base);
    const SplitReference ref = renderSplitReference(base, src, 1, quick);
    Settings uniform = withEstimator(base, EstimatorKind::uniform);
    uniform.render.samples = 16;
    Settings restir = withEstimator(base, EstimatorKind::restir);
    restir.render.source = LightSource::tree;
    restir.restir.bias_correction = BiasCorrection::pairwise;  // unbiased; with visibility reuse it loses ~4% (docs/experiments.md)
    const std::uint32_t seeds = quick ? 3 : 25;
    std::vector<double> gains, tr, tu, er, eu;
    for (std::uint32_t k = 0; k < seeds; ++k) {
        uniform.render.seed = restir.render.seed = k;
        const ExperimentRender u = renderForExperiment(uniform, src, 1, 1);
        const ExperimentRender r = renderForExperiment(restir, src, 1, 1);
        eu.push_back(correctedRelMse(u.image, ref.image));
        er.push_back(correctedRelMse(r.image, ref.image));
        tu.push_back(u.frameSeconds);
        tr.push_back(r.frameSeconds);
        gains.push_back(eu.back() * tu.back() / tr.back() / er.back());
    }
    const double gain = median(gains), t = median(tr);
    figures["restir_vs_uniform_100k_320x180"] = {
        {"configuration", "restir:pairwise:tree"}, {"seeds", seeds},
        {"reference", ref.json},
        {"restir_relMSE_median", median(er)}, {"restir_frame_s_median", t},
        {"uniform_16spp_relMSE_median", median(eu)}, {"uniform_frame_s_median", median(tu)},
        {"equal_time_gains", gains}, {"equal_time_gain_median", gain}};
    // Bar: the restir frame's time against the time uniform needs for its
    // error (the median gain), at most 1/5.
    bars["restir_vs_uniform_equal_time"] = bar(t, t * gain, 0.2);
}

/// Scaling curves over particles and resolution (CSV and PNG).
void Suite::benchScaling() {
    const Settings restir = restirScene();
    std::string csvP = "particles,bvh_build_s,restir_frame_s,trace_shadow_rays_s,shadow_rays\n";
    std::vector<std::uint32_t> counts = {10'000, 30'000, 100'000, 300'000, 1'000'000};
    if (quick) counts.pop_back();
    for (std::uint32_t n : counts) {
        log(fmt::format("scaling: {} particles", n));
        Settings s = restir;
        s.particles.count = n;
        const ParticleSource src(s);
        const FrameTiming t = timeFrames(s, src, 2, 2, 1);
        csvP += fmt::format("{},{:.6f},{:.6f},{:.6f},{}\n", n, t.seconds(Pass::buildClusters), t.frameSeconds,
                            t.seconds(Pass::traceShadowRays), t.shadowRays);
    }
    writeFileAtomic(outDir + "/scaling_particles.csv", csvP);
    std::string csvR = "width,height,pixels,restir_frame_s,trace_gbuffer_s\n";
    for (auto [w, h] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{640, 360}, {960, 540}, {1280, 720}, {1920, 1080}}) {
        log(fmt::format("scaling: {}x{}", w, h));
        Settings s = restir;
        s.camera.width = w;
        s.camera.height = h;
        const FrameTiming t = timeFrames(s, diskSource, 2, 2, 1);
        csvR += fmt::format("{},{},{},{:.6f},{:.6f}\n", w, h, std::uint64_t(w) * h, t.frameSeconds, t.seconds(Pass::traceGBuffer));
    }
    writeFileAtomic(outDir + "/scaling_resolution.csv", csvR);
    try {
        plotPng(outDir + "/scaling_particles.png",
                "set datafile separator ','\nset key top left\nset grid\nset logscale xy\nset xlabel 'particles'\n"
                "set ylabel 'seconds'\nplot '" + outDir + "/scaling_particles.csv' every ::1 using 1:2 with linespoints title "
                "'buildClusters', '' every ::1 using 1:3 with linespoints title 'restir frame (720p)', '' every ::1 using 1:4 "
                "with linespoints title 'traceShadowRays'\n");
        plotPng(outDir + "/scaling_resolution.png",
                "set datafile separator ','\nset key top left\nset grid\nset xlabel 'pixels'\nset ylabel 'seconds'\n"
                "plot '" + outDir + "/scaling_resolution.csv' every ::1 using 3:4 with linespoints title 'restir frame "
                "(100K particles)', '' every ::1 using 3:5 with linespoints title 'traceGBuffer'\n");
    } catch (const std::exception& e) {
        log(fmt::format("no plot: {}", e.what()));
    }
}

/// Peak resident memory per particle (a child process per count).
void Suite::benchMemory() {
    {
        nlohmann::json mem;
        std::vector<std::uint32_t> sizes = {100'000, 1'000'000};
        long base = 0;
        for (std::uint32_t n : sizes) {
            log(fmt::format("peak memory: {} particles", n));
            // The child's own high-water mark (its stats.json), so the suite's memory does not count.
            const auto dir = std::filesystem::temp_directory_path() / "accretion_suite_mem";
            const std::string out = (dir / "m.exr").string();
            long rss = -1;
            if (runChild({binary, "render", scene, "--quiet", "--frames", "0:1", "-D", fmt::format("particles.count={}", n), "-o", out})) {
                std::ifstream in(dir / "m.stats.json");
                rss = nlohmann::json::parse(in)["peak_rss_bytes"].get<long>();
            }
            mem[fmt::format("peak_rss_bytes_{}", n)] = rss;
            mem[fmt::format("bytes_per_particle_{}", n)] = rss > 0 ? double(rss) / n : 0.0;
            if (n == sizes[0]) base = rss;
            else if (rss > 0 && base > 0) mem["marginal_bytes_per_particle"] = double(rss - base) / double(n - sizes[0]);
        }
        figures["memory"] = mem;
    }
}

/// What each skip of the frame plan saves: the same frames with and without the work.
void Suite::benchPlanSkips() {
    const Settings restir = restirScene();
    {
        log("pass-plan skips, 100K particles at 640x360");
        nlohmann::json skips;
        Settings base = diskScene(scene, 100'000, 640, 360);
        base.render.estimator = EstimatorKind::restir;
        auto frame = [&](const Settings& s, bool rebuild = false) {
            const ParticleSource src(s);
            return timeFrames(s, src, 2, 1, 3, rebuild).frameSeconds;
        };
        auto primaryPass = [&](const Settings& s) {
            const ParticleSource src(s);
            return timeFrames(s, src, 2, 1, 3).seconds(Pass::traceGBuffer);
        };
        auto pair = [&](const std::string& name, double with, double without) {
            skips[name] = {{"with_work_s", with}, {"skipped_s", without}, {"saved_s", with - without}};
        };
        Settings st = base;
        st.particles.gm = 0.0;
        pair("static_scene_one_bvh_build", frame(st, true), frame(st));
        Settings alpha = base;
        alpha.geometry.alpha = AlphaMode::disc;
        // The disc also removes coverage (less lighting work), so only the primary pass is compared.
        pair("no_alpha_no_filter_callbacks_traceGBuffer", primaryPass(alpha), primaryPass(base));
        Settings vis = base;
        vis.shading.visibility = false;
        pair("visibility_off_no_shadow_rays", frame(base), frame(vis));
        Settings once = base;
        once.restir.temporal = false;
        pair("temporal_off_no_history", frame(base), frame(once));
        Settings dark = base;
        dark.shading.albedo = Vec3(0.0f);
        pair("albedo_0_no_lighting", frame(base), frame(dark));
        Settings counting = base;
        counting.gpu.counters = true;
        pair("counters_off_no_counting_code", frame(counting), frame(base));
        figures["plan_skips_640x360"] = skips;
    }
}

/// Micro-benchmarks of the hot kernels (Google Benchmark, its JSON embedded).
void Suite::benchMicro() {
    if (!micro.empty()) {
        log("micro-benchmarks");
        const auto file = std::filesystem::temp_directory_path() / "accretion_suite_micro.json";
        if (runChild({micro, "--benchmark_filter=BM_(Alias|LightTree|Target|Reservoir)", "--benchmark_repetitions=5",
                      "--benchmark_report_aggregates_only=true", "--benchmark_out=" + file.string(),
                      "--benchmark_out_format=json"})) {
            std::ifstream in(file);
            nlohmann::json m;
            const nlohmann::json doc = nlohmann::json::parse(in);  // held: a range-for over a temporary's member dangles
            for (const auto& b : doc["benchmarks"])
                if (b.value("aggregate_name", "") == "median")
                    m[b["run_name"].get<std::string>()] = {{"ns", b["real_time"]}, {"items_per_s", b["items_per_second"]}};
            figures["micro_benchmarks_median"] = m;
        }
    }
}

/// The bars against their limits.
void printBars(const nlohmann::json& bars) {
    Table t({{"bar", "bar", -26}, {"project_s", "project s", 12, "{:.5f}"}, {"limit_s", "limit s", 12, "{:.5f}"},
             {"ratio", "ratio", 8, "{:.2f}"}, {"limit_ratio", "bar", 8, "{:.2f}"}, {"", "", 0, "{}", "{}", true, "  "}});
    for (const auto& [name, b] : bars.items())
        t.add({name, b["project_s"].get<double>(), b["limit_s"].get<double>(), b["ratio"].get<double>(),
               b["limit_ratio"].get<double>(), b["ratio"].get<double>() <= b["limit_ratio"].get<double>() ? "ok" : "ABOVE"});
    fmt::print("{}", t.console());
}

int main(int argc, char** argv) {
    CLI::App app{"accretion performance suite: bars against bare Embree loops, scaling curves, memory"};
    bool quick = false;
    std::string outDir = "bench", binary = "build/accretion", micro = "build/bench/accretion_bench",
                scene = "scenes/disk_100k.toml";
    app.add_flag("--quick", quick, "Skip the tree 1% reference and the 1M-particle frame (for CI smoke runs)");
    app.add_option("--out", outDir, "Directory of results.json and the scaling CSV/PNG");
    app.add_option("--accretion", binary, "The accretion binary (memory runs)");
    app.add_option("--scene", scene, "The disk scene");
    app.add_option("--micro", micro, "The Google Benchmark micro-benchmarks binary (empty: skip)");
    std::vector<std::string> only;
    app.add_option("--only", only,
                   "Run only these sections (bvh, bvh_1m, rays, restir_frame, tree, split, restir_sources, scaling, memory, "
                   "plan, micro) and merge their bars and figures into the existing results.json, each marked with "
                   "this commit")
        ->delimiter(',');
    CLI11_PARSE(app, argc, argv);
    std::filesystem::create_directories(outDir);
    Suite suite(scene);
    suite.quick = quick;
    suite.outDir = outDir;
    suite.binary = binary;
    suite.micro = micro;
    nlohmann::json results = {{"version", std::string(version())},
                              {"machine", {{"cpu", machine()}, {"cores", suite.cores}}},
                              {"scene", scene},
                              {"quick", quick}};
    const std::vector<std::pair<std::string, std::function<void()>>> sections = {
        {"bvh", [&] { suite.benchBvhRebuild(); }},
        {"bvh_1m", [&] { suite.benchBvhRebuild1M(); }},
        {"rays", [&] { suite.benchRays(); }},
        {"restir_frame", [&] { suite.benchRestirFrame(); }},
        {"tree", [&] { if (!quick) suite.benchTreeReference(); }},
        {"split", [&] { suite.benchSplitReference(); }},
        {"restir_sources", [&] { suite.benchRestirSources(); }},
        {"scaling", [&] { suite.benchScaling(); }},
        {"memory", [&] { suite.benchMemory(); }},
        {"plan", [&] { suite.benchPlanSkips(); }},
        {"micro", [&] { if (!micro.empty()) suite.benchMicro(); }}};
    for (const std::string& name : only)
        if (std::none_of(sections.begin(), sections.end(), [&](const auto& sec) { return sec.first == name; })) {
            fmt::print(stderr, "accretion_suite: --only {}: no such section\n", name);
            return 2;
        }
    for (const auto& [name, run] : sections)
        if (only.empty() || std::find(only.begin(), only.end(), name) != only.end()) run();

    if (only.empty()) {
        results["bars"] = suite.bars;
        results["figures"] = suite.figures;
    } else {
        // Merge: the sections run now replace their entries in the last
        // results, each entry naming the commit and machine it was measured on.
        const std::filesystem::path last = outDir + "/results.json";
        if (std::filesystem::exists(last)) results = nlohmann::json::parse(std::ifstream(last));
        const nlohmann::json at = {{"version", std::string(version())}, {"cpu", machine()}, {"cores", suite.cores}};
        for (auto& [key, part] : {std::pair<const char*, nlohmann::json*>{"bars", &suite.bars}, {"figures", &suite.figures}})
            for (auto& [name, value] : part->items()) {
                results[key][name] = value;
                if (results[key][name].is_object()) results[key][name]["measured_at"] = at;
                else results[key][name] = {{"value", value}, {"measured_at", at}};
            }
        results["partial_runs"].push_back({{"sections", only}, {"measured_at", at}});
    }
    std::ofstream(outDir + "/results.json.tmp") << results.dump(2) << "\n";
    std::filesystem::rename(outDir + "/results.json.tmp", outDir + "/results.json");
    printBars(suite.bars);
    fmt::print("{}\n", suite.figures.dump(2));
    fmt::print("results: {}/results.json, scaling: {}/scaling_particles.csv/.png, {}/scaling_resolution.csv/.png\n", outDir,
               outDir, outDir);
    return 0;
}
