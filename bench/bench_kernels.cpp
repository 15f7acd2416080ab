// Micro-benchmarks of the hot kernels of light sampling and resampling, on
// the lights of the 100K-particle disk (items/s = samples, terms or merges):
//   BM_AliasSample        power-proportional light selection (alias table)
//   BM_LightTreeSample    light-tree importance sampling at a receiver
//   BM_TargetPdf          p_hat = luminance(f I G) of a random light (the RIS target)
//   BM_ReservoirUpdate    streaming RIS update of one candidate
//   BM_ReservoirMerge     merging a reused reservoir
// Run: ./build/bench/accretion_bench --benchmark_filter='BM_(Alias|LightTree|Target|Reservoir)'
#include <benchmark/benchmark.h>

#include "accretion/core/rng.h"
#include "accretion/lighting/light_arrays.h"
#include "accretion/lighting/light_sampler.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/lighting/reservoir.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/estimators.h"

using namespace accretion;

namespace {

struct Lights {
    Settings s;
    Particles p;
    LightArrays L;
    Lights() {
        s.particles.count = 100'000;
        s.particles.radius = 0.02;
        p = ParticleSource(s).frame(0);
        L = LightArrays(p, s.shading);
    }
    /// A receiver on particle j, facing up.
    ShadingPoint receiver(std::uint32_t j) const {
        return {p.position[j], Vec3(0, 1, 0), Vec3(0, 1, 0), p.albedo[j], j};
    }
};

const Lights& lights() {
    static const Lights l;  // built once per benchmark process
    return l;
}

void BM_AliasSample(benchmark::State& state) {
    const Lights& l = lights();
    const AliasTable table = buildPowerTable(l.p);
    Rng rng(1, 0, RngPass::lightSampling, 0);
    std::uint64_t sum = 0;
    for (auto _ : state) sum += sampleSource<true>(l.L, &table, rng).i;
    benchmark::DoNotOptimize(sum);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_AliasSample);

void BM_LightTreeSample(benchmark::State& state) {
    const Lights& l = lights();
    const LightTree tree(l.p, l.s.shading);
    Rng rng(2, 0, RngPass::lightSampling, 0);
    std::uint64_t sum = 0;
    std::uint32_t j = 0;
    for (auto _ : state) {
        const ShadingPoint sp = l.receiver(j);
        j = (j + 7919) % l.L.count;
        sum += tree.sample(sp, rng).i;
    }
    benchmark::DoNotOptimize(sum);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LightTreeSample);

void BM_TargetPdf(benchmark::State& state) {
    const Lights& l = lights();
    Rng rng(3, 0, RngPass::lightSampling, 0);
    const ShadingPoint sp = l.receiver(12345);
    float sum = 0.0f;
    for (auto _ : state) sum += l.L.targetPdf<ShadingModel::lambert>(sp, rng.uniformInt(l.L.countBound));
    benchmark::DoNotOptimize(sum);
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_TargetPdf);

/// A reservoir's streaming step: update (one candidate, RIS) or merge (a
/// reservoir of M = 20, reuse), the same stream of weights.
template <bool Merge>
void BM_Reservoir(benchmark::State& state) {
    Rng rng(Merge ? 5 : 4, 0, Merge ? RngPass::restirSpatial : RngPass::restirCandidates, 0);
    Reservoir r;
    std::uint32_t x = 0;
    for (auto _ : state) {
        if constexpr (Merge) r.merge(x++, rng.uniform(), 0.5f, 20, rng.uniform());
        else r.update(x++, rng.uniform(), 0.5f, rng.uniform());
        benchmark::DoNotOptimize(r);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_Reservoir<false>)->Name("BM_ReservoirUpdate");
BENCHMARK(BM_Reservoir<true>)->Name("BM_ReservoirMerge");

}  // namespace
