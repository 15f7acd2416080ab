// Micro-benchmarks of the foundation's hot paths, on the 100K-particle disk:
//   BM_BuildClusters/<policy>  clustering + all BLAS + TLAS of one frame
//   BM_ShadowRays/<estimator>  estimateLighting at 1280x720 (rays/s counter)
// Run: ./build/bench/accretion_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include "accretion/geometry/particle_bvh.h"
#include "accretion/particles/particle_source.h"
#include "accretion/geometry/camera.h"
#include "accretion/render/estimators.h"
#include "accretion/render/gbuffer.h"

using namespace accretion;

namespace {

Settings diskSettings(std::uint32_t count) {
    Settings s;
    s.particles.count = count;
    s.particles.radius = 0.02;  // smaller particles for the denser disk
    s.camera.width = 1280;
    s.camera.height = 720;
    return s;
}

Particles disk(const Settings& s, std::uint32_t frame) { return ParticleSource(s).frame(frame); }

/// Frame 0 of the disk, built, with its G-buffer traced.
struct BuiltFrame {
    explicit BuiltFrame(const Settings& settings)
        : s(settings), p(disk(s, 0)), cam(Camera::atFrame(s.camera, 0)), bvh(device, s.geometry) {
        bvh.build(p, cam);
        traceGBuffer(bvh, p, cam, s.shading.model, gb);
    }
    Settings s;
    Particles p;
    Camera cam;
    EmbreeDevice device;
    ParticleBvh bvh;
    GBuffer gb;
};

void BM_BuildClusters(benchmark::State& state) {
    Settings s = diskSettings(std::uint32_t(state.range(0)));
    s.geometry.build = static_cast<BuildPolicy>(state.range(1));
    const Particles p0 = disk(s, 0), p1 = disk(s, 1);
    const Camera cam = Camera::atFrame(s.camera, 0);
    EmbreeDevice device;
    ParticleBvh bvh(device, s.geometry);
    bvh.build(p0, cam);
    int frame = 0;
    for (auto _ : state) bvh.build(++frame % 2 ? p1 : p0, cam);
    state.counters["clusters"] = double(bvh.stats().clusters);
    state.counters["embree_MB"] = double(bvh.stats().embreeBytes) / 1e6;
    state.SetLabel(std::string(enumName(s.geometry.build)));
}
BENCHMARK(BM_BuildClusters)
    ->ArgsProduct({{100'000}, {int(BuildPolicy::rebuild), int(BuildPolicy::refit), int(BuildPolicy::fast_trace)}})
    ->Args({1'000'000, int(BuildPolicy::rebuild)})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_ShadowRays(benchmark::State& state) {
    Settings s = diskSettings(100'000);
    s.render.estimator = static_cast<EstimatorKind>(state.range(0));
    s.render.samples = 8;
    const BuiltFrame f(s);
    const AliasTable table = buildPowerTable(f.p);
    LightingImage out;
    std::uint64_t rays = 0;
    for (auto _ : state) {
        LightingInputs in{f.bvh, f.p, f.gb, s.shading, s.render, 0, &table};
        rays += estimateLighting(in, out).shadowRays;
    }
    state.counters["shadow_rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
    state.SetLabel(std::string(enumName(s.render.estimator)));
}
BENCHMARK(BM_ShadowRays)->Arg(int(EstimatorKind::uniform))->Arg(int(EstimatorKind::power))
    ->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_TraceGBuffer(benchmark::State& state) {
    BuiltFrame f(diskSettings(100'000));
    std::uint64_t rays = 0;
    for (auto _ : state) rays += traceGBuffer(f.bvh, f.p, f.cam, f.s.shading.model, f.gb);
    state.counters["primary_rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_TraceGBuffer)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
