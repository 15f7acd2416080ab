// The shared ReSTIR steps (accretion/render/restir_steps.h) run where they
// run: each step on the GPU, in a CUDA kernel (one thread per case), and on
// the CPU (this program's host code, compiled by the host compiler), on the
// same inputs. Every result must agree bit for bit, except neighbourPoint,
// whose cos and sin are the device's cosf/sinf on one side and libm on the
// other: its points must agree within the bound CUDA documents for them
// (2 ulp of cos and sin, scaled by the radius, plus one ulp of the sum), and
// its texels wherever the host's point is not within that bound of a
// rounding boundary. Prints one line per step and "shared_core_check: PASS"
// or the first disagreements and "FAIL" (exit 1). Without a GPU: exit 2.
//   nvcc -std=c++20 -fmad=false ... tests/twin/shared_core_check.cu src/geometry/camera.cpp
// scripts/compile_twin.sh compiles it on every CI run; bench/gpu/run.sh's
// shared_core step runs it on the lent GPU (results in bench/gpu/results).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <cuda_runtime.h>

#include "accretion/core/rng.h"
#include "accretion/render/light_estimates.h"
#include "accretion/render/restir_passes.h"
#include "accretion/render/sample_sums.h"
#include "accretion/render/restir_steps.h"
#include "accretion/lighting/light_tree.h"
#include "accretion/render/particle_split_passes.h"
#include "accretion/render/voxel_cache_passes.h"

namespace {

using namespace accretion;

/// One case's results as raw 32-bit words (floats by their bits).
struct Out {
    std::uint32_t w[8];
};

ACC_HD std::uint32_t bits(float v) {
    std::uint32_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
}

// ---------------------------------------------------------------- the cases
// Each case is one ACC_HD function of its index and its inputs: the kernel
// and the host loop call the same function.

constexpr int kNeighbours = 4096, kReprojections = 4096, kCaps = 512, kCandidates = 1024, kCombines = 3000, kShades = 600;

ACC_HD void neighbourCase(int k, Out& o) {
    PortableRng rng(std::uint64_t(k), 1, RngPass::restirSpatial, 5);
    const std::uint32_t W = 64 + k % 7, H = 36 + k % 5, x = k % W, y = (k / 3) % H;
    const float radius = 1.0f + float(k % 40);
    float fx, fy;
    restir::neighbourPoint(rng, radius, x, y, fx, fy);
    std::size_t q = 0;
    const bool ok = restir::neighbourTexel(fx, fy, x, y, W, H, q);
    PortableRng again(std::uint64_t(k), 1, RngPass::restirSpatial, 5);
    std::size_t q2 = 0;
    const bool ok2 = restir::drawNeighbour(again, radius, x, y, W, H, q2);  // the composition the passes call
    o = Out{{bits(fx), bits(fy), std::uint32_t(ok), ok ? std::uint32_t(q) : 0u, std::uint32_t(ok2), ok2 ? std::uint32_t(q2) : 0u,
             bits(radius), 0u}};
}

ACC_HD void reprojectCase(int k, const Camera& cam, const Vec3* points, Out& o) {
    std::size_t q = 0;
    float depth = 0.0f;
    const bool half = k % 2;
    const bool ok = restir::reprojectPoint(cam, points[k], half ? 0.5f : 1.0f, half ? 160 : 320, half ? 90 : 180, q, depth);
    o = Out{{std::uint32_t(ok), ok ? std::uint32_t(q) : 0u, ok ? bits(depth) : 0u, 0u, 0u, 0u, 0u, 0u}};
}

/// particle_split.texel_point: a texel's receiver uv, centre, jittered or antithetic,
/// in the opaque square or the disc, on grids of side 1-4, over frames.
constexpr int kTexelPoints = 4096;
ACC_HD void texelPointCase(int k, Out& o) {
    const std::uint32_t side = 1 + std::uint32_t(k) % 4, sub = (std::uint32_t(k) / 4) % (side * side);
    TexelPointRule rule;
    rule.mode = TexelPoint((k / 64) % 3);  // centre, jittered, antithetic
    rule.disc = (k / 256) % 2 != 0;
    rule.frame = std::uint32_t(k) % 13;
    rule.seed = 11 + std::uint64_t(k) / 1024;
    const Vec2 uv = texelPointUv(std::uint32_t(k) * 2654435761u, sub, side, rule);
    o = Out{{bits(uv.x), bits(uv.y), side, sub, std::uint32_t(rule.mode), std::uint32_t(rule.disc), 0u, 0u}};
}

ACC_HD void capCase(int k, Out& o) {
    const std::uint32_t m = restir::capHistoryM(std::uint32_t(k) * 37u, std::uint32_t(k) % 9u, 0.5 + 0.25 * (k % 80));
    o = Out{{m, 0u, 0u, 0u, 0u, 0u, 0u, 0u}};
}

/// Candidates of a fixed stream: the odd zero-pdf candidate, the odd
/// non-finite weight (p_hat 1e38 over pdf 1e-3).
struct CandidateDraw {
    ACC_HD LightSample operator()(PortableRng& g) const {
        const std::uint32_t i = static_cast<std::uint32_t>(g.uniform() * 1000.0f);
        return LightSample{i, i % 97 == 0 ? 0.0f : 0.001f};
    }
};
struct CandidateTarget {
    ACC_HD float operator()(std::uint32_t i) const { return i % 211 == 0 ? 1e38f : float(i % 13) * 0.125f; }
};

ACC_HD void candidatesCase(int k, Out& o) {
    PortableRng rng(std::uint64_t(k), 2, RngPass::restirCandidates, 3);
    int rejects = 0;
    Reservoir r;
    const bool kept = restir::resampleCandidates(1 + k % 32, rng, CandidateDraw{}, CandidateTarget{},
                                                 [&] { return ++rejects > 100; }, r);
    o = Out{{std::uint32_t(kept), std::uint32_t(rejects), r.y, bits(r.w_sum), bits(r.p_hat), bits(r.W), r.M, 0u}};
}

/// Domains whose p_hat is a fixed function of (domain, light): zero for a
/// few pairs, so basic's support and pairwise's zero branches are taken.
struct TableDomains {
    const StoredReservoir* r;
    std::uint32_t n;
    ACC_HD std::uint32_t count() const { return n; }
    ACC_HD const StoredReservoir& reservoir(std::uint32_t i) const { return r[i]; }
    ACC_HD static float pHat(std::uint32_t i, std::uint32_t y) {
        const std::uint32_t h = (i * 2654435761u) ^ (y * 40503u);
        return h % 7 == 0 ? 0.0f : float(h % 1000 + 1) * 0.001f;
    }
    ACC_HD float targetPdf(std::uint32_t i, std::uint32_t y) const { return pHat(i, y); }
    ACC_HD bool supports(std::uint32_t i, std::uint32_t y) const { return pHat(i, y) > 0.0f; }
    ACC_HD void countTerm() const {}
};

ACC_HD void combineCase(int k, const StoredReservoir* offers, Out& o) {
    const TableDomains d{offers + std::size_t(k) * restir::kMaxOffers, 1 + std::uint32_t(k % restir::kMaxOffers)};
    const BiasCorrection bias = k % 3 == 0 ? BiasCorrection::none : k % 3 == 1 ? BiasCorrection::basic : BiasCorrection::pairwise;
    PortableRng rng(std::uint64_t(k), 4, RngPass::restirTemporal, 9);
    const StoredReservoir out = restir::combineReservoirs(d, bias, rng);
    o = Out{{out.y, bits(out.W), out.M, bits(out.p_hat), 0u, 0u, 0u, 0u}};
}

ACC_HD void shadeCase(int k, const float* in, Out& o) {
    const float* v = in + 4 * k;
    const LightTerm t{Vec3(v[0], v[1], k % 50 == 0 ? 3e38f : v[2]), Vec3(0.0f, 0.0f, 1.0f), 1.0f};
    Vec3 Lr(0.0f);
    const restir::Shade s = restir::shadeSample(t, 100.0f * v[3], k % 4 != 0, Lr);
    const StoredReservoir occ = restir::occludedReservoir(StoredReservoir{7u, 1.0f, std::uint32_t(k), 0.5f});
    o = Out{{std::uint32_t(s), bits(Lr.x), bits(Lr.y), bits(Lr.z), occ.y, bits(occ.W), occ.M, bits(occ.p_hat)}};
}

// ---------------------------------------------------------------- the passes
// The reuse passes' bodies (restir_passes.h) over a bridge of plain arrays,
// the same on both sides: a W x H lighting grid whose texel px holds
// particle px (most texels) at a point last frame's camera sees near texel
// px, so that reprojection lands on, beside or off its texel; p_hat a fixed
// function of (the domain's particle, the light), as TableDomains.

constexpr std::uint32_t kGridW = 48, kGridH = 27;

struct PassInputs {
    restir::ReuseParams params;
    BiasCorrection bias;
    const GBufferTexel* texels;       ///< this frame's (and, here, last frame's) grid
    const StoredReservoir* in;        ///< the pass's input
    const StoredReservoir* history;   ///< last frame's reservoirs
    const Vec3* historyPositions;     ///< last frame's particle centres (and, here, this frame's lights)
    std::uint32_t particles;
    Camera camera;                    ///< last frame's
    const Vec3* emission;             ///< the lights' I (particle px: light px)
};

/// Domains keyed by the particle of each offer's texel.
struct KeyDomains {
    const StoredReservoir* r;
    const std::uint32_t* key;
    std::uint32_t n;
    ACC_HD std::uint32_t count() const { return n; }
    ACC_HD const StoredReservoir& reservoir(std::uint32_t i) const { return r[i]; }
    ACC_HD float targetPdf(std::uint32_t i, std::uint32_t y) const { return TableDomains::pHat(key[i], y); }
    ACC_HD bool supports(std::uint32_t i, std::uint32_t y) const { return targetPdf(i, y) > 0.0f; }
    ACC_HD void countTerm() const {}
};

struct CheckBridge {
    using Rng = PortableRng;
    template <std::uint32_t N>
    struct Offers {
        const CheckBridge& b;
        StoredReservoir r[N];
        std::uint32_t key[N];
        std::uint32_t n = 0;
        ACC_HD void addCurrent(const StoredReservoir& x, const GBufferTexel& g) { r[n] = x, key[n++] = g.particle; }
        ACC_HD void addHistory(const StoredReservoir& x, std::size_t q) { r[n] = x, key[n++] = b.in.texels[q].particle ^ 0x55u; }
        ACC_HD StoredReservoir combine(PortableRng& rng) const { return restir::combineReservoirs(KeyDomains{r, key, n}, b.in.bias, rng); }
    };
    const PassInputs& in;
    StoredReservoir& out;   ///< the texel's output (a body writes its own texel alone)
    std::uint32_t* reuses;  ///< accepted, rejected of this texel

    ACC_HD const restir::ReuseParams& params() const { return in.params; }
    ACC_HD GBufferTexel texel(std::size_t px) const { return in.texels[px]; }
    ACC_HD StoredReservoir input(std::size_t px) const { return in.in[px]; }
    ACC_HD void output(std::size_t, const StoredReservoir& r) const { out = r; }
    ACC_HD restir::NoRecorder recorder(std::size_t, const GBufferTexel&) const { return {}; }
    ACC_HD std::uint32_t reservoirBytes() const { return 16; }
    // Each outcome, and each bound M cap, leaves its own trace in the counts compared.
    ACC_HD void reuse(ReuseOutcome o) const { reuses[kept(o) ? 0 : 1] += 1u + (std::uint32_t(o) << 4); }
    ACC_HD void historyCapped() const { reuses[0] += 1u << 20; }
    template <std::uint32_t N>
    ACC_HD Offers<N> offers() const { return Offers<N>{*this}; }
    ACC_HD bool historyHas(std::uint32_t j) const { return j < in.particles; }
    ACC_HD Vec3 historyPosition(std::uint32_t j) const { return in.historyPositions[j]; }
    ACC_HD const Camera& historyCamera() const { return in.camera; }
    ACC_HD GBufferTexel historyTexel(std::size_t q) const { return in.texels[q]; }
    ACC_HD StoredReservoir historyReservoir(std::size_t q) const { return in.history[q]; }
    // The lights: particle j at historyPositions[j] with emission[j], lambert
    // (the real evalLight, on both sides); visibility a fixed function of the
    // pair, so both branches of every test are taken.
    Vec3* Lr = nullptr;
    ACC_HD ShadingPoint shadingPoint(const GBufferTexel& g) const {
        const Vec3 c = in.historyPositions[g.particle];
        return {c + g.local, g.normal, g.geomNormal, Vec3(0.7f), g.particle, c, g.local};
    }
    ACC_HD bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        if (i == sp.self || i >= in.particles) return false;
        return evalLight<ShadingModel::lambert>(sp, in.historyPositions[i], in.emission[i], 0.01f, t);
    }
    ACC_HD float targetPdf(const ShadingPoint& sp, std::uint32_t i) const {
        LightTerm t;
        return lightTerm(sp, i, t) ? luminance(t.value) : 0.0f;
    }
    ACC_HD void countLightTerm() const {}
    ACC_HD bool shadows() const { return true; }
    ACC_HD bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm&, restir::NoRecorder&) const {
        return (sp.self * 31u + i) % 5u != 0u;
    }
    ACC_HD void occluded() const { ++reuses[1]; }
    ACC_HD bool dropOccludedCandidates() const { return in.bias != BiasCorrection::none; }
    ACC_HD bool visibilityReuse() const { return in.bias == BiasCorrection::pairwise; }
    ACC_HD void writeLr(std::size_t, const Vec3& v) const { *Lr = v; }
    ACC_HD void keep(std::size_t, const StoredReservoir& r) const { out = r; }
    ACC_HD bool reject(std::size_t) const { return ++reuses[0] % 2 == 0; }
};

/// render.source uniform over the particles, as the check draws it.
struct UniformSource {
    std::uint32_t lights;
    struct Drawer {
        std::uint32_t lights;
        ACC_HD LightSample sample(PortableRng& g) const { return {g.uniformInt(lights), 1.0f / float(lights)}; }
    };
    ACC_HD std::uint32_t reads() const { return 0; }
    ACC_HD std::uint32_t gathers() const { return 0; }
    ACC_HD Drawer at(const ShadingPoint&, std::uint32_t, std::uint32_t, PortableRng&) const { return {lights}; }
};

/// Case k: texel k % (W H) of pass k / (W H): under none, basic and
/// pairwise, generateCandidates, temporal, spatial (iterations 1 and 3) and
/// traceShadowRays (candidate visibility and visibility reuse with the bias).
constexpr int kPassKinds = 5;
constexpr int kPassCases = 3 * kPassKinds * int(kGridW * kGridH);

ACC_HD void passCase(int k, const PassInputs* variants, Out& o) {
    const std::uint32_t texels = kGridW * kGridH;
    const std::size_t px = std::size_t(k) % texels;
    const int variant = k / int(texels);  // bias x kind
    const PassInputs& in = variants[variant / kPassKinds];
    StoredReservoir r;
    Vec3 Lr(-1.0f);
    std::uint32_t reuses[2] = {0, 0};
    CheckBridge b{in, r, reuses};
    b.Lr = &Lr;
    const std::uint32_t x = std::uint32_t(px % kGridW), y = std::uint32_t(px / kGridW);
    switch (variant % kPassKinds) {
    case 0: restir::generateCandidatesTexel(b, UniformSource{in.particles}, px, x, y); break;
    case 1: restir::temporalResamplingTexel(b, px); break;
    case 2: restir::spatialResamplingTexel(b, px, x, y, 1); break;
    case 3: restir::spatialResamplingTexel(b, px, x, y, 3); break;
    case 4: restir::traceShadowRayTexel(b, px); break;
    }
    o = Out{{r.y, bits(r.W), r.M, bits(r.p_hat), reuses[0], reuses[1], bits(Lr.x), bits(Lr.y) ^ bits(Lr.z)}};
}

// ---------------------------------------------------------------- the light loops
// light_estimates.h's loops of the Monte Carlo estimators on the same grid
// and lights: exact's sum over every light at texel k, and 64 uniform
// samples (8 chunks of 8, each chunk's lights drawn first) into SampleSums.

struct LightLoopBridge {
    static constexpr bool traced = false;
    const CheckBridge& lights;
    ACC_HD bool lightTerm(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const { return lights.lightTerm(sp, i, t); }
    ACC_HD void countLightTerm() const {}
    ACC_HD bool seen(const ShadingPoint& sp, std::uint32_t i, const LightTerm& t) const {
        restir::NoRecorder rec;
        return lights.visible(sp, i, t, rec);
    }
};

constexpr int kLoopCases = 2 * int(kGridW * kGridH);

ACC_HD std::uint32_t lo(double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    return std::uint32_t(u) ^ std::uint32_t(u >> 32);
}

ACC_HD void loopCase(int k, const PassInputs* variants, Out& o) {
    const std::uint32_t texels = kGridW * kGridH;
    const std::size_t px = std::size_t(k) % texels;
    const PassInputs& in = variants[0];
    StoredReservoir unused;
    std::uint32_t counts[2] = {0, 0};
    const CheckBridge lights{in, unused, counts};
    LightLoopBridge b{lights};
    const GBufferTexel g = in.texels[px];
    o = Out{};
    if (!g.hit()) return;
    const ShadingPoint sp = lights.shadingPoint(g);
    if (k < int(texels)) {
        const DVec3 sum = sumLightTerms(b, sp, LightRange{in.particles});
        o = Out{{lo(sum.x), lo(sum.y), lo(sum.z), 1u, 0u, 0u, 0u, 0u}};
        return;
    }
    SampleSums sums;
    for (std::uint32_t chunk = 0; chunk < 8; ++chunk) {
        PortableRng rng(px, 2, RngPass::lightSampling, 7, chunk + 1);
        LightSample xs[8];
        for (LightSample& x : xs) x = LightSample{rng.uniformInt(in.particles), 1.0f / float(in.particles)};
        shadeLightSamples(b, sp, xs, 8, DVec3(0.0), sums);
    }
    o = Out{{lo(sums.sum.x), lo(sums.sum.y), lo(sums.sum.z), lo(sums.sumSq.x), lo(sums.sumSq.y), lo(sums.sumSq.z), sums.n, 2u}};
}

// ---------------------------------------------------------------- the voxel cache
// voxel_cache_passes.h's bodies over a bridge of plain arrays, on the
// passes' lights: a grid over them, every third cell unoccupied, last
// frame's cells a fixed function of the cell; lights uniform from the
// cell's stream, visibility a fixed function of (cell, light). Case k <
// kVoxelCells updates cell k; the rest shade each texel of the passes' grid
// in l1 and camera (lambert) and isotropic.

constexpr std::uint32_t kVoxelNx = 20, kVoxelNy = 8, kVoxelNz = 14;
constexpr int kVoxelCells = int(kVoxelNx * kVoxelNy * kVoxelNz);
constexpr int kVoxelCases = kVoxelCells + 3 * int(kGridW * kGridH);

struct VoxelCheckBridge {
    const PassInputs& in;
    const voxel::VoxelParams& p;
    voxel::VoxelCell* written;
    Vec3* Lr;
    ACC_HD const voxel::VoxelParams& params() const { return p; }
    ACC_HD bool occupied(std::uint32_t c) const { return c % 3u != 0u; }
    ACC_HD voxel::CellRay cellRay(std::uint32_t c, std::uint32_t r) const { return voxel::traceCellRay(*this, c, r); }
    ACC_HD voxel::VoxelCell cell(std::uint32_t c) const {
        voxel::VoxelCell v;
        v.A = Vec3(float(c % 7u), float(c % 5u), float(c % 3u)) * 0.5f;
        v.Bx = Vec3(0.1f * float(c % 11u) - 0.5f);
        v.By = Vec3(0.05f * float(c % 13u));
        v.Bz = Vec3(-0.02f * float(c % 17u));
        v.C = 0.3f * v.A;
        v.frames = float(c % 4u);
        return v;
    }
    ACC_HD void writeCell(std::uint32_t, const voxel::VoxelCell& v) const { *written = v; }
    ACC_HD LightSample sampleLight(const ShadingPoint&, PortableRng& g) const {
        return {g.uniformInt(in.particles), 1.0f / float(in.particles)};
    }
    ACC_HD bool cellTerm(const ShadingPoint& sp, std::uint32_t i, float minDist2, LightTerm& t) const {
        if (i >= in.particles) return false;
        return evalLight<ShadingModel::isotropic>(sp, in.historyPositions[i], in.emission[i], minDist2 > 0.01f ? minDist2 : 0.01f, t);
    }
    ACC_HD bool shadows() const { return true; }
    ACC_HD bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm&) const { return (bits(sp.x.x) ^ (i * 7u)) % 5u != 0u; }
    ACC_HD GBufferTexel pixel(std::size_t px) const { return in.texels[px]; }
    ACC_HD ShadingPoint shadingPoint(const GBufferTexel& g) const {
        const Vec3 c = in.historyPositions[g.particle];
        return {c + g.local, g.normal, g.geomNormal, Vec3(0.7f), g.particle, c, g.local};
    }
    ACC_HD void writePixelLr(std::size_t, const Vec3& v) const { *Lr = v; }
};

ACC_HD void voxelCase(int k, const PassInputs* variants, const voxel::VoxelParams* params, Out& o) {
    const PassInputs& in = variants[0];
    voxel::VoxelCell c;
    Vec3 Lr(-1.0f);
    if (k < kVoxelCells) {
        VoxelCheckBridge b{in, params[0], &c, &Lr};
        voxel::updateVoxelCell(b, std::uint32_t(k));
        o = Out{{bits(c.A.x), bits(c.A.y), bits(c.A.z), bits(c.Bx.x), bits(c.By.y), bits(c.Bz.z), bits(c.C.x), bits(c.frames)}};
        return;
    }
    const std::uint32_t texels = kGridW * kGridH;
    const int variant = (k - kVoxelCells) / int(texels);
    const std::size_t px = std::size_t(k - kVoxelCells) % texels;
    VoxelCheckBridge b{in, params[variant == 1 ? 1 : 0], &c, &Lr};
    if (variant == 2) voxel::shadeVoxelPixel<ShadingModel::isotropic>(b, px);
    else voxel::shadeVoxelPixel<ShadingModel::lambert>(b, px);
    o = Out{{bits(Lr.x), bits(Lr.y), bits(Lr.z), 3u, 0u, 0u, 0u, 0u}};
}

// ---------------------------------------------------------------- particle_split
// particle_split_passes.h's bodies over a bridge of plain arrays, on the
// passes' lights and the light tree built over them (LightTree, host):
// case k < texels searches light k's 16 nearest; the rest shade each texel
// of the passes' grid (texel px: particle px, one texel each) with 16 near
// and no far, 8 near and 4 far draws, and 8 near and 4 far each kept by
// RIS among 4 with a history (even particles: a fixed last Lr), its far
// mean's alone, a running-mean start, 12 far draws without history
// (far_new: the odd particles), and a new texel started from its near
// lights' far means (far_prior), every texel's far mean shown blended
// with theirs (far_share), and its far history following a near set that
// changed since last frame (far_handoff: last frame's set a fixed function
// of this one's, the near terms kept hashed).
// Visibility is a fixed function of (point, light).

constexpr int kSplitVariants = 10;
constexpr int kSplitCases = (1 + kSplitVariants) * int(kGridW * kGridH);

struct SplitCheckBridge {
    const PassInputs& in;
    LightTreeView view;
    const std::uint64_t* paths;
    const psplit::SplitParams& p;
    Out& o;
    ACC_HD const psplit::SplitParams& params() const { return p; }
    ACC_HD std::uint32_t particleOfSlot(std::uint32_t v) const { return v; }
    ACC_HD Vec3 particlePosition(std::uint32_t j) const { return in.historyPositions[j]; }
    ACC_HD std::uint64_t lightPath(std::uint32_t j) const { return paths[j]; }
    ACC_HD const LightTreeView& tree() const { return view; }
    ACC_HD void writeNear(std::uint32_t, const std::uint32_t* light, std::uint32_t count, float radius2) const {
        std::uint32_t h = 0;
        for (std::uint32_t m = 0; m < count; ++m) h = h * 0x9e3779b1u + light[m];
        o = Out{{count, bits(radius2), h, count ? light[0] : 0u, count ? light[count - 1] : 0u, 4u, 0u, 0u}};
    }
    ACC_HD GBufferTexel texel(std::size_t q) const { return in.texels[q]; }
    ACC_HD ShadingPoint shadingPoint(const GBufferTexel& g) const {
        const Vec3 c = in.historyPositions[g.particle];
        return {c + g.local, g.normal, g.geomNormal, Vec3(0.7f), g.particle, c, g.local};
    }
    ACC_HD std::uint32_t nearLights(std::uint32_t v, std::uint32_t* light) const {
        float d2[psplit::kMaxNear];
        return psplit::nearestLights(view, in.historyPositions[v], v, paths[v], p.nearCount, light, d2);
    }
    ACC_HD std::uint32_t nearLight(std::uint32_t v, std::uint32_t m) const {
        std::uint32_t light[psplit::kMaxNear];
        return m < nearLights(v, light) ? light[m] : psplit::kNoNearLight;
    }
    ACC_HD float nearRadius2(std::uint32_t v) const {
        std::uint32_t light[psplit::kMaxNear];
        float d2[psplit::kMaxNear];
        const std::uint32_t n = psplit::nearestLights(view, in.historyPositions[v], v, paths[v], p.nearCount, light, d2);
        return n ? d2[n - 1] : 0.0f;
    }
    ACC_HD psplit::SplitRay splitRay(std::size_t q, std::uint32_t r) const { return psplit::traceSplitRay(*this, q, r); }
    ACC_HD LightSample sampleFar(const ShadingPoint& sp, PortableRng& rng, const psplit::FarImportance& imp) const {
        return view.sample(sp, rng, imp);
    }
    ACC_HD bool term(const ShadingPoint& sp, std::uint32_t i, LightTerm& t) const {
        if (i >= in.particles) return false;
        return evalLight<ShadingModel::lambert>(sp, in.historyPositions[i], in.emission[i], 0.01f, t);
    }
    ACC_HD bool shadows() const { return true; }
    ACC_HD bool visible(const ShadingPoint& sp, std::uint32_t i, const LightTerm&) const { return (bits(sp.x.x) ^ (i * 7u)) % 5u != 0u; }
    ACC_HD void reject(std::size_t) const {}
    ACC_HD bool historyTexelOf(std::uint32_t j, std::uint32_t, std::size_t& q) const {
        q = j;
        return j % 2u == 0u;
    }
    ACC_HD Vec3 historyLr(std::size_t q) const { return Vec3(0.1f * float(q % 7u), 0.2f, 0.05f * float(q % 3u)); }
    ACC_HD void writeTexelLr(std::size_t, const Vec3& Lr) const {
        o.w[0] = bits(Lr.x);
        o.w[1] = bits(Lr.y);
        o.w[2] = bits(Lr.z);
        o.w[3] = 5u;
    }
    ACC_HD Vec3 historyFar(std::size_t q) const { return Vec3(0.03f * float(q % 5u), 0.07f, 0.02f * float(q % 4u)); }
    ACC_HD std::uint32_t historyAge(std::size_t q) const { return q % 4u; }
    ACC_HD void writeTexelAge(std::size_t, std::uint32_t n) const { o.w[4] = n; }
    ACC_HD void writeTexelFar(std::size_t, const Vec3& far) const {
        o.w[5] = bits(far.x);
        o.w[6] = bits(far.y);
        o.w[7] = bits(far.z);
    }
    /// Last frame's near set: this one's with every third light replaced by
    /// a light index shifted by 5, and one light fewer where it is long.
    ACC_HD std::uint32_t historyNearLights(std::uint32_t v, std::uint32_t* light) const {
        std::uint32_t n = nearLights(v, light);
        for (std::uint32_t m = 0; m < n; m += 3) light[m] = (light[m] + 5u) % in.particles;
        return n > 4 ? n - 1 : n;
    }
    ACC_HD Vec3 historyNearValue(std::size_t q, std::uint32_t m) const { return Vec3(0.01f * float((q + m) % 9u), 0.02f * float(m), 0.05f); }
    /// The near terms, hashed where history_start mean would write the age.
    ACC_HD void writeTexelNear(std::size_t, std::uint32_t m, const Vec3& v) const {
        o.w[4] = o.w[4] * 0x9e3779b1u + (bits(v.x) ^ bits(v.y) * 3u ^ bits(v.z) * 7u ^ m);
    }
};

ACC_HD void splitCase(int k, const PassInputs* variants, const LightTreeView* tree, const std::uint64_t* paths,
                      const psplit::SplitParams* params, Out& o) {
    const PassInputs& in = variants[0];
    const std::uint32_t texels = kGridW * kGridH;
    const int variant = k / int(texels);
    const std::size_t px = std::size_t(k) % texels;
    o = Out{};
    SplitCheckBridge b{in, *tree, paths, params[variant], o};
    if (variant == 0) psplit::findNearLightsOf(b, std::uint32_t(px));
    else psplit::sumSplitTexel(b, px);
}

// ---------------------------------------------------------------- the hosts

struct Inputs {
    Camera cam;
    Vec3* points;
    StoredReservoir* offers;
    float* shades;
    PassInputs* passes;  ///< none, basic, pairwise
    voxel::VoxelParams* voxel;  ///< l1, camera
    LightTreeView* tree;        ///< the light tree over the passes' lights
    std::uint64_t* paths;       ///< its lights' paths
    psplit::SplitParams* split; ///< the near search; the ten texel variants
};

enum class Step { neighbours, reprojections, caps, candidates, combines, shades, passes, loops, voxels, splits, texelPoints };
constexpr Step kSteps[] = {Step::neighbours, Step::reprojections, Step::caps, Step::candidates, Step::combines, Step::shades,
                           Step::passes, Step::loops, Step::voxels, Step::splits, Step::texelPoints};

ACC_HD int caseCount(Step s) {
    switch (s) {
        case Step::neighbours: return kNeighbours;
        case Step::reprojections: return kReprojections;
        case Step::caps: return kCaps;
        case Step::candidates: return kCandidates;
        case Step::combines: return kCombines;
        case Step::shades: return kShades;
        case Step::passes: return kPassCases;
        case Step::loops: return kLoopCases;
        case Step::voxels: return kVoxelCases;
        case Step::splits: return kSplitCases;
        case Step::texelPoints: return kTexelPoints;
    }
    return 0;
}

ACC_HD void runCase(Step s, int k, const Inputs& in, Out& o) {
    switch (s) {
        case Step::neighbours: neighbourCase(k, o); break;
        case Step::reprojections: reprojectCase(k, in.cam, in.points, o); break;
        case Step::caps: capCase(k, o); break;
        case Step::candidates: candidatesCase(k, o); break;
        case Step::combines: combineCase(k, in.offers, o); break;
        case Step::shades: shadeCase(k, in.shades, o); break;
        case Step::passes: passCase(k, in.passes, o); break;
        case Step::loops: loopCase(k, in.passes, o); break;
        case Step::voxels: voxelCase(k, in.passes, in.voxel, o); break;
        case Step::splits: splitCase(k, in.passes, in.tree, in.paths, in.split, o); break;
        case Step::texelPoints: texelPointCase(k, o); break;
    }
}

__global__ void runCases(Step s, Inputs in, Out* out) {
    const int k = int(blockIdx.x * blockDim.x + threadIdx.x);
    if (k < caseCount(s)) runCase(s, k, in, out[k]);
}

const char* stepName(Step s) {
    switch (s) {
        case Step::neighbours: return "neighbourPoint/neighbourTexel/drawNeighbour";
        case Step::reprojections: return "reprojectPoint";
        case Step::caps: return "capHistoryM";
        case Step::candidates: return "resampleCandidates";
        case Step::combines: return "combineReservoirs";
        case Step::shades: return "shadeSample/occludedReservoir";
        case Step::passes: return "the pass bodies (restir_passes.h)";
        case Step::loops: return "exact and uniform loops (light_estimates.h)";
        case Step::voxels: return "the voxel cache's bodies (voxel_cache_passes.h)";
        case Step::splits: return "particle_split's bodies (particle_split_passes.h)";
        case Step::texelPoints: return "texelPointUv (particle_texels.h)";
    }
    return "?";
}

#define CHECK_CUDA(x)                                                                            \
    do {                                                                                         \
        const cudaError_t e = (x);                                                               \
        if (e != cudaSuccess) {                                                                  \
            std::fprintf(stderr, "shared_core_check: %s: %s\n", #x, cudaGetErrorString(e));      \
            std::exit(e == cudaErrorNoDevice || e == cudaErrorInsufficientDriver ? 2 : 1);       \
        }                                                                                        \
    } while (0)

template <class T>
T* toDevice(const std::vector<T>& v) {
    T* d = nullptr;
    CHECK_CUDA(cudaMalloc(&d, v.size() * sizeof(T)));
    CHECK_CUDA(cudaMemcpy(d, v.data(), v.size() * sizeof(T), cudaMemcpyHostToDevice));
    return d;
}

float asFloat(std::uint32_t u) {
    float f;
    std::memcpy(&f, &u, sizeof f);
    return f;
}

/// One ulp at |v|.
double ulpOf(float v) { return double(std::nextafter(std::abs(v), INFINITY)) - double(std::abs(v)); }

/// Distance of t to the nearest rounding boundary of lround (k + 0.5).
double toBoundary(float t) { return std::abs(double(t) - (std::floor(double(t)) + 0.5)); }

/// The neighbour case's agreement: the points within the bound, the texels
/// equal unless the host's point lies within the bound of a boundary, and
/// drawNeighbour equal to its parts on each side. worstRatio: the largest
/// |device - host| over its bound (<= 1 passes).
bool neighbourAgrees(const Out& h, const Out& d, double& worstRatio, int& boundaryCases) {
    const float radius = asFloat(h.w[6]);
    bool ok = true;
    for (int c = 0; c < 2; ++c) {
        const float fh = asFloat(h.w[c]), fd = asFloat(d.w[c]);
        // cosf/sinf: 2 ulp of a value in [-1, 1] (CUDA C Programming Guide,
        // table of single-precision functions), times r <= radius; then the
        // product (|r cos| <= radius) and the sum round once each: an ulp of
        // each. r and phi are IEEE operations (sqrt, *), the same on both.
        const double bound = double(radius) * 2.0 * 0x1p-24 + ulpOf(radius) + ulpOf(fh);
        const double diff = std::abs(double(fh) - double(fd));
        worstRatio = std::max(worstRatio, diff / bound);
        ok = ok && diff <= bound;
        if (toBoundary(fh) <= bound) ++boundaryCases;
    }
    const double near = double(radius) * 2.0 * 0x1p-24 + ulpOf(radius) + ulpOf(64.0f);  // the bound for any point under 64
    const bool nearBoundary = toBoundary(asFloat(h.w[0])) <= near || toBoundary(asFloat(h.w[1])) <= near;
    if (!nearBoundary) ok = ok && h.w[2] == d.w[2] && h.w[3] == d.w[3] && h.w[4] == d.w[4] && h.w[5] == d.w[5];
    ok = ok && h.w[2] == h.w[4] && h.w[3] == h.w[5] && d.w[2] == d.w[4] && d.w[3] == d.w[5];  // drawNeighbour = its parts
    return ok;
}

}  // namespace

int main() {
    int devices = 0;
    if (cudaGetDeviceCount(&devices) != cudaSuccess || devices == 0) {
        std::fprintf(stderr, "shared_core_check: no CUDA device\n");
        return 2;
    }
    cudaDeviceProp prop{};
    CHECK_CUDA(cudaGetDeviceProperties(&prop, 0));

    // The inputs, drawn once on the host from a fixed stream.
    PortableRng in(7, 3, RngPass::restirSpatial, 11);
    std::vector<Vec3> points(kReprojections);
    for (Vec3& p : points) p = Vec3(20.0f * in.uniform() - 10.0f, 2.0f * in.uniform() - 1.0f, 20.0f * in.uniform() - 10.0f);
    std::vector<StoredReservoir> offers(std::size_t(kCombines) * restir::kMaxOffers);
    for (int k = 0; k < kCombines; ++k)
        for (std::uint32_t i = 0; i < 1 + std::uint32_t(k % restir::kMaxOffers); ++i) {
            const std::uint32_t y = static_cast<std::uint32_t>(in.uniform() * 5000.0f);
            const float W = in.uniform() < 0.1f ? 0.0f : 10.0f * in.uniform();
            offers[std::size_t(k) * restir::kMaxOffers + i] =
                StoredReservoir{y, W, 1u + static_cast<std::uint32_t>(in.uniform() * 40.0f), TableDomains::pHat(i, y)};
        }
    std::vector<float> shades(4 * kShades);
    for (float& v : shades) v = in.uniform();
    // The passes' grid: particle px at a point near texel px's ray, seen by
    // last frame's camera; a tenth of the texels empty.
    const Camera gridCam = Camera::lookAt(Vec3(0.0f, 2.0f, 30.0f), Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 40.0, kGridW, kGridH);
    const std::uint32_t texels = kGridW * kGridH;
    std::vector<GBufferTexel> grid(texels);
    std::vector<Vec3> centres(texels);
    std::vector<StoredReservoir> current(texels), history(texels);
    for (std::uint32_t px = 0; px < texels; ++px) {
        const float depth = 20.0f + 10.0f * in.uniform();
        const Vec3 point = gridCam.position + depth * gridCam.pixelDirection(px % kGridW, px / kGridW);
        GBufferTexel& g = grid[px];
        g.particle = in.uniform() < 0.1f ? kNoParticle : px;
        g.local = Vec3(0.2f * in.uniform() - 0.1f, 0.2f * in.uniform() - 0.1f, 0.0f);
        g.normal = glm::normalize(Vec3(0.3f * in.uniform() - 0.15f, 0.3f * in.uniform() - 0.15f, 1.0f));
        g.geomNormal = g.normal;
        float fx, fy;
        gridCam.project(point, fx, fy, g.depth);
        // Last frame the particle sat within about a texel of where it is now.
        centres[px] = point - g.local + Vec3(0.06f * in.uniform() - 0.03f, 0.06f * in.uniform() - 0.03f, 0.0f);
        const auto reservoir = [&] {
            const std::uint32_t y = static_cast<std::uint32_t>(in.uniform() * 5000.0f);
            return StoredReservoir{y, in.uniform() < 0.1f ? 0.0f : 10.0f * in.uniform(), 1u + static_cast<std::uint32_t>(in.uniform() * 40.0f),
                                   TableDomains::pHat(px, y)};
        };
        current[px] = reservoir();
        history[px] = reservoir();
    }
    GBufferTexel* dGrid = toDevice(grid);
    StoredReservoir *dCurrent = toDevice(current), *dHistory = toDevice(history);
    Vec3* dCentres = toDevice(centres);
    std::vector<Vec3> emission(texels);
    for (Vec3& I : emission) I = in.uniform() < 0.05f ? Vec3(0.0f) : Vec3(in.uniform(), in.uniform(), in.uniform()) * 50.0f;
    Vec3* dEmission = toDevice(emission);
    std::vector<PassInputs> hostPasses, devicePasses;
    for (const BiasCorrection bias : {BiasCorrection::none, BiasCorrection::basic, BiasCorrection::pairwise}) {
        const restir::ReuseParams params{.frame = 5, .seed = 9, .width = kGridW, .height = kGridH, .normalThreshold = 0.95f,
                                         .depthThreshold = 0.1f, .mCap = 20.0, .candidates = 12, .neighbours = 8, .radius = 6.0f};
        hostPasses.push_back({params, bias, grid.data(), current.data(), history.data(), centres.data(), texels, gridCam, emission.data()});
        devicePasses.push_back({params, bias, dGrid, dCurrent, dHistory, dCentres, texels, gridCam, dEmission});
    }

    // The voxel grid over the passes' points (depth 20-30 before the camera
    // at z = 30), in l1 and camera bases.
    std::vector<voxel::VoxelParams> voxels(2);
    for (int b = 0; b < 2; ++b) {
        voxel::VoxelParams& v = voxels[b];
        v.grid.lower = Vec3(-12.0f, -4.0f, -2.0f);
        v.grid.cellSize = 1.2f;
        v.grid.invCellSize = 1.0f / 1.2f;
        v.grid.nx = kVoxelNx, v.grid.ny = kVoxelNy, v.grid.nz = kVoxelNz;
        v.rays = 6;
        v.history = 3.0f;
        v.nearClamp2 = b == 0 ? 0.0f : 0.36f;  // camera: half a cell
        v.basis = b == 0 ? VoxelBasis::l1 : VoxelBasis::camera;
        v.frame = 4;
        v.seed = 13;
        v.camera = gridCam.position;
        v.facesPlane = false;
    }
    // particle_split: the light tree over the passes' lights (lambert), one
    // texel a particle; the near search's and the ten texel variants' settings.
    Particles lights;
    lights.position = centres;
    lights.emission = emission;
    lights.radius.assign(texels, 0.05f);
    ShadingSettings lambert;
    lambert.dmin = 0.1;
    const LightTree lightTree(lights, lambert);
    LightTreeView hostTree = lightTree.view(), deviceTree = hostTree;
    deviceTree.nodes = toDevice(lightTree.nodes());
    std::vector<std::uint64_t> paths = lightTree.paths();
    std::vector<psplit::SplitParams> splits(1 + kSplitVariants);
    for (std::size_t v = 0; v < splits.size(); ++v) {
        psplit::SplitParams& s = splits[v];
        s.nearCount = v <= 1 ? 16 : 8;
        s.farSamples = v <= 1 ? 0 : 4;
        s.candidates = v >= 3 ? 4 : 1;
        s.history = v >= 3 ? 0.6f : 0.0f;
        s.historyOfFar = v == 4 || v == 6 || v >= 8;  // the far mean's history alone
        s.historyMean = v >= 5;             // a running mean over the texel's age first
        s.farNew = v == 7 ? 12 : 0;         // far_new: a texel without history draws 12
        s.farPrior = v == 8 ? 8 : 0;        // far_prior: and starts from its near lights' far means
        s.farShare = v == 9 ? 24 : 0;       // far_share: every texel shown blended with them
        s.farHandoff = v == 10;             // far_handoff: the far history follows the near set (no running mean: the near terms' hash in the age's word)
        if (v == 10) s.historyMean = false;
        s.visible = texels;
        s.frame = 3;
        s.seed = 21;
    }
    const Inputs host{Camera::lookAt(Vec3(0.0f, 7.0f, 17.0f), Vec3(0.0f), Vec3(0.0f, 1.0f, 0.0f), 45.0, 320, 180), points.data(),
                      offers.data(), shades.data(), hostPasses.data(), voxels.data(), &hostTree, paths.data(), splits.data()};
    const Inputs device{host.cam, toDevice(points), toDevice(offers), toDevice(shades), toDevice(devicePasses), toDevice(voxels),
                        toDevice(std::vector<LightTreeView>{deviceTree}), toDevice(paths), toDevice(splits)};

    std::printf("shared_core_check: %s, CUDA %d.%d; host results from the host compiler, device results from sm_%d%d\n",
                prop.name, CUDART_VERSION / 1000, (CUDART_VERSION % 1000) / 10, prop.major, prop.minor);
    bool pass = true;
    for (const Step s : kSteps) {
        const int n = caseCount(s);
        std::vector<Out> onHost(n), onDevice(n);
        for (int k = 0; k < n; ++k) runCase(s, k, host, onHost[k]);
        Out* d = nullptr;
        CHECK_CUDA(cudaMalloc(&d, n * sizeof(Out)));
        runCases<<<(n + 127) / 128, 128>>>(s, device, d);
        CHECK_CUDA(cudaGetLastError());
        CHECK_CUDA(cudaMemcpy(onDevice.data(), d, n * sizeof(Out), cudaMemcpyDeviceToHost));
        CHECK_CUDA(cudaFree(d));
        int differ = 0, bitDiffer = 0, boundary = 0, shown = 0;
        double worst = 0.0;
        for (int k = 0; k < n; ++k) {
            const bool same = std::memcmp(&onHost[k], &onDevice[k], sizeof(Out)) == 0;
            bitDiffer += !same;
            const bool ok = s == Step::neighbours ? neighbourAgrees(onHost[k], onDevice[k], worst, boundary) : same;
            if (ok) continue;
            ++differ;
            if (shown++ < 5) {
                std::printf("  %s case %d: host", stepName(s), k);
                for (std::uint32_t w : onHost[k].w) std::printf(" %08x", w);
                std::printf(" / device");
                for (std::uint32_t w : onDevice[k].w) std::printf(" %08x", w);
                std::printf("\n");
            }
        }
        if (s == Step::passes) {
            std::uint64_t accepted = 0, rejected = 0;
            for (const Out& o : onHost) accepted += o.w[4], rejected += o.w[5];
            std::printf("%-44s %5d cases: %d differ in some bit (offers accepted and values rejected %llu; offers rejected and samples occluded %llu)\n", stepName(s), n, differ,
                        (unsigned long long)accepted, (unsigned long long)rejected);
        } else if (s == Step::neighbours)
            std::printf("%-44s %5d cases: %d outside the bound; %d differ in some bit, worst |device - host| = %.3f of the "
                        "bound; %d coordinates within the bound of a rounding boundary\n",
                        stepName(s), n, differ, bitDiffer, worst, boundary);
        else
            std::printf("%-44s %5d cases: %d differ in some bit\n", stepName(s), n, differ);
        pass = pass && differ == 0;
    }
    std::printf("shared_core_check: %s\n", pass ? "PASS" : "FAIL");
    return pass ? 0 : 1;
}
