// accretion tune: the GPU frame's configuration for a time budget. It
// searches the configuration space with the calibrated cost model for the
// GPU time (`accretion cost` of each configuration at the scene's
// resolution) and the CPU for the error (`accretion bias` of each lighting
// configuration over seeds at a small resolution, against a reference),
// prints the Pareto front of predicted GPU ms against relMSE, marks biased
// configurations and recommends the best one under the budget.
//
// The search is separable: the acceleration structure's layout, build
// policy and alpha path change no image (docs/MODEL.md section 2), so they
// are chosen by predicted time alone, at the scene's lighting; the lighting
// configurations are then measured for error and priced on that geometry.
// Every measurement is a child process whose result is cached by a hash of
// everything it depends on (the accretion version included), so a second
// run reads them back. The GPU time is priced here from the cached
// counters, with gpu.coefficients' calibration (the committed one by
// default), so that a new calibration re-prices without measuring again.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/bias_test.h"
#include "accretion/analysis/experiment.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/analysis/view_check.h"
#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/parse.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/read_file.h"
#include "accretion/core/rng.h"
#include "accretion/core/stop_signal.h"
#include "accretion/core/version.h"
#include "accretion/gpu/cost_model.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "accretion/io/stats_writer.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/pixel_window.h"
#include "child_process.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct TuneArgs : SceneArgs {
    double budgetMs = 0.0;
    std::optional<double> maxError;
    std::uint32_t seeds = 4;  ///< every configuration's first measurement; more where they decide the answer (verifyCandidates)
    std::optional<std::uint32_t> frame;  ///< default: render.frame_start + the steady state's history
    std::string errorCrops = "4x2";     ///< strata of the frame, one crop each: COLUMNSxROWS
    std::string cropSize = "160x90";    ///< each crop's size at the scene's resolution
    std::uint32_t cropMargin = 32;      ///< the pixels around a crop restir renders for its reuse
    std::string space = "quick";
    std::vector<std::string> designs{"restir", "particle_restir", "voxel_cache", "particle_split"};
    std::vector<std::string> references;  ///< --reference: one per crop
    std::uint32_t referenceSpp = 1024;
    std::string out, cache;
    bool allowBiased = false;
    bool anatomy = false;          ///< also the error with every light visible: visibility's share
    double biasBoundPct = 1.0;     ///< the energy bias a verdict of "unbiased" must be able to see
    std::uint32_t maxSeeds = 48;   ///< the most seeds tune spends on one configuration to see it
    std::string errorsFrom;        ///< --errors-from: a previous tune's JSON whose error measurements are reused
};

/// One point of the space: its label and the settings it overrides.
/// A geometry choice (none changes the image): the acceleration layout and
/// cluster size, the build policy, and for disc alpha a 4-state micromap
/// instead of the any-hit.
struct GeometryChoice {
    std::string layoutLabel;                 ///< "clusters of 100", "one BLAS", ...
    AccelLayout layout = AccelLayout::clusters;
    std::optional<std::uint32_t> clusterSize;  ///< geometry.cluster_size (none: the layout's own)
    BuildPolicy build = BuildPolicy::rebuild;
    bool omm = false;                        ///< gpu.omm = 4state at level 4 (else off)

    std::string label() const { return fmt::format("{}, {}{}", layoutLabel, enumName(build), omm ? ", 4-state micromap L4" : ""); }
    /// As -D overrides of the measurements' child processes (and their cache keys).
    std::vector<std::string> defines() const {
        std::vector<std::string> d = {fmt::format("geometry.layout={}", enumName(layout))};
        if (clusterSize) d.push_back(fmt::format("geometry.cluster_size={}", *clusterSize));
        d.push_back(fmt::format("geometry.build={}", enumName(build)));
        if (omm) d.insert(d.end(), {"gpu.omm=4state", "gpu.omm_level=4"});
        else d.push_back("gpu.omm=off");
        return d;
    }
};

/// The geometry choices: layout and cluster size, rebuild or refit (every
/// layout's refit is timed: bench/gpu/layouts_refit.txt), and for disc
/// alpha the any-hit or a 4-state micromap (not for boxes).
std::vector<GeometryChoice> geometryChoices(const Settings& s) {
    constexpr std::uint32_t kAll = 10000000;
    std::vector<GeometryChoice> layouts = {{"clusters of 100", AccelLayout::clusters, 100u},
                                           {"clusters of 1000", AccelLayout::clusters, 1000u},
                                           {"clusters of 10000", AccelLayout::clusters, 10000u},
                                           {"one BLAS", AccelLayout::clusters, kAll},
                                           {"instance per particle", AccelLayout::instances, std::nullopt}};
    if (s.geometry.primitive == Primitive::billboard) layouts.push_back({"one BLAS of boxes", AccelLayout::aabbs, kAll});
    std::vector<GeometryChoice> out;
    for (const GeometryChoice& l : layouts)
        for (const BuildPolicy build : {BuildPolicy::rebuild, BuildPolicy::refit})
            for (const bool omm : {false, true}) {
                if (omm && (s.geometry.alpha != AlphaMode::disc || l.layout == AccelLayout::aabbs)) continue;
                GeometryChoice g = l;
                g.build = build;
                g.omm = omm;
                out.push_back(g);
            }
    return out;
}

/// particle_split's texel history and how a particle new to the view
/// starts (docs/designs.md): the settings of [particle_split] past its
/// rays, each at its default unless set.
struct SplitHistory {
    TexelPoint point = TexelPoint::centre;
    HistoryStart start = HistoryStart::first;
    HistoryOf of = HistoryOf::all;
    std::uint32_t farNew = 0, farPrior = 0, farShare = 0;
    bool farHandoff = false;

    /// " anti mean far-only prior32 share256 handoff": the settings not at their defaults.
    std::string label() const {
        std::string l;
        if (point != TexelPoint::centre) l += point == TexelPoint::antithetic ? " anti" : " jitter";
        if (start == HistoryStart::mean) l += " mean";
        if (of == HistoryOf::far) l += " far-only";
        if (farNew) l += fmt::format(" new{}", farNew);
        if (farPrior) l += fmt::format(" prior{}", farPrior);
        if (farShare) l += fmt::format(" share{}", farShare);
        if (farHandoff) l += " handoff";
        return l;
    }
    /// The -D overrides of the settings not at their defaults.
    std::vector<std::string> defines() const {
        std::vector<std::string> d;
        if (point != TexelPoint::centre) d.push_back(fmt::format("particle_split.texel_point={}", enumName(point)));
        if (start != HistoryStart::first) d.push_back(fmt::format("particle_split.history_start={}", enumName(start)));
        if (of != HistoryOf::all) d.push_back(fmt::format("particle_split.history_of={}", enumName(of)));
        if (farNew) d.push_back(fmt::format("particle_split.far_new={}", farNew));
        if (farPrior) d.push_back(fmt::format("particle_split.far_prior={}", farPrior));
        if (farShare) d.push_back(fmt::format("particle_split.far_share={}", farShare));
        if (farHandoff) d.push_back("particle_split.far_handoff=true");
        return d;
    }
};

/// The design a lighting choice runs: restir per pixel, particle_restir
/// per particle texel (texels per side, reservoirs a texel, how the pixels
/// read them), voxel_cache in world cells (cells along the longest side,
/// rays a cell, its basis), or particle_split per particle texel (near
/// lights, far rays, candidates a far ray, the texels' history).
struct Design {
    EstimatorKind estimator = EstimatorKind::restir;
    std::uint32_t texels = 1, texelRays = 1;
    PixelShading shading = PixelShading::interpolate;
    std::uint32_t cells = 64, cellRays = 8;
    VoxelBasis basis = VoxelBasis::camera;
    std::uint32_t near = 16, far = 8, farCandidates = 8;
    double history = 0.75;
    SplitHistory splitHistory{};
};

/// A lighting choice: its design (restir or particle_restir), candidate
/// source and count, spatial neighbours and iterations, bias correction,
/// visibility reuse (with basic, V tested at the neighbours too: unbiased;
/// pairwise cannot) and the lighting resolution (restir).
struct LightingChoice {
    LightSource source = LightSource::power;
    std::uint32_t candidates = 8;
    std::uint32_t neighbours = 0, iterations = 1;
    BiasCorrection bias = BiasCorrection::basic;
    bool visibilityReuse = false;
    double scale = 1.0;
    Design design{};

    bool particles() const { return design.estimator == EstimatorKind::particle_restir; }
    bool voxels() const { return design.estimator == EstimatorKind::voxel_cache; }
    bool split() const { return design.estimator == EstimatorKind::particle_split; }
    std::string label() const {
        if (split())
            return fmt::format("split near={} far={} C={} h={:g} {}x{}{}", design.near, design.far, design.farCandidates, design.history,
                               design.texels, design.texels, design.splitHistory.label());
        if (voxels())
            return fmt::format("voxels {} cells={} rays={} {}", enumName(source), design.cells, design.cellRays, enumName(design.basis));
        if (particles())
            return fmt::format("particles {} M={} {}x{}xK{} nb={}x{} {}{} {}", enumName(source), candidates, design.texels,
                               design.texels, design.texelRays, neighbours, iterations, enumName(bias), visibilityReuse ? "+vis" : "",
                               enumName(design.shading));
        return fmt::format("{} M={} nb={}x{} {}{} {:g}x", enumName(source), candidates, neighbours, iterations, enumName(bias),
                           visibilityReuse ? "+vis" : "", scale);
    }
    /// As -D overrides of the measurements' child processes (and their cache keys).
    std::vector<std::string> defines() const {
        if (voxels())  // the cache's own settings alone: restir's would only split its cache keys
            return {"render.estimator=voxel_cache", fmt::format("render.source={}", enumName(source)),
                    fmt::format("voxel.cells={}", design.cells), fmt::format("voxel.rays={}", design.cellRays),
                    fmt::format("voxel.basis={}", enumName(design.basis))};
        if (split()) {  // its own settings alone, as the voxel cache's
            std::vector<std::string> d = {"render.estimator=particle_split", fmt::format("particle_split.near={}", design.near),
                                          fmt::format("particle_split.far={}", design.far),
                                          fmt::format("particle_split.candidates={}", design.farCandidates),
                                          fmt::format("particle_split.history={:g}", design.history),
                                          fmt::format("particle_split.texels={}", design.texels)};
            for (std::string& o : design.splitHistory.defines()) d.push_back(std::move(o));
            return d;
        }
        std::vector<std::string> d = restirDefines();
        if (particles()) {
            d.front() = "render.estimator=particle_restir";
            d.push_back(fmt::format("restir.texels={}", design.texels));
            d.push_back(fmt::format("restir.texel_rays={}", design.texelRays));
            d.push_back(fmt::format("restir.pixel_shading={}", enumName(design.shading)));
        }
        return d;
    }

private:
    std::vector<std::string> restirDefines() const {
        return {"render.estimator=restir",
                fmt::format("render.source={}", enumName(source)),
                fmt::format("render.candidates={}", candidates),
                fmt::format("restir.spatial_neighbours={}", neighbours),
                fmt::format("restir.spatial_iterations={}", iterations),
                fmt::format("restir.bias_correction={}", enumName(bias)),
                fmt::format("restir.visibility_reuse={}", visibilityReuse),
                fmt::format("restir.basic_visibility={}", visibilityReuse && bias == BiasCorrection::basic),
                fmt::format("restir.resolution_scale={:g}", scale)};
    }
};

/// The lighting choices of `space`: quick, 34 restir points around the GPU
/// team's settings, 8 of particle_restir, 2 of voxel_cache and 12 of
/// particle_split; full, the whole grids (hours).
std::vector<LightingChoice> lightingChoices(const std::string& space) {
    struct Axes {
        std::vector<LightSource> sources;
        std::vector<std::uint32_t> candidates;
        std::vector<std::pair<std::uint32_t, std::uint32_t>> spatial;  // neighbours, iterations
        std::vector<BiasCorrection> corrections;
        std::vector<bool> visibility;
        std::vector<double> scales;
    };
    using enum BiasCorrection;
    Axes x;
    if (space == "full") {
        x = {{LightSource::uniform, LightSource::power, LightSource::tree}, {4, 8, 16, 32}, {{0, 1}, {3, 1}, {5, 1}, {5, 2}, {10, 1}},
             {none, basic, pairwise}, {false, true}, {1.0, 0.75, 0.5}};
    } else if (space == "quick") {
        x = {{LightSource::power, LightSource::tree}, {8, 32}, {{0, 1}, {5, 1}}, {basic, pairwise}, {false}, {1.0, 0.5}};
    } else {
        throw InputError(fmt::format("command line --space {}: expected quick or full", space));
    }
    std::vector<LightingChoice> out;
    for (const LightSource src : x.sources)
        for (std::uint32_t m : x.candidates)
            for (const auto& [nb, it] : x.spatial)
                for (const BiasCorrection bc : x.corrections)
                    for (bool vis : x.visibility)
                        for (double scale : x.scales) out.push_back({src, m, nb, it, bc, vis, scale});
    if (space == "quick") {  // a biased correction and visibility reuse, beside the grid
        out.push_back({LightSource::tree, 16, 5, 1, none, false, 1.0});
        out.push_back({LightSource::tree, 16, 5, 1, pairwise, true, 1.0});
    }
    // particle_restir (docs/designs.md): tree candidates, temporal reuse by
    // id, the pixels interpolating K reservoirs a particle; beside them its
    // unbiased form (the pixels resample), world neighbours and 2x2 texels.
    const auto particles = [](std::uint32_t texels, std::uint32_t rays, PixelShading shading = PixelShading::interpolate) {
        return Design{EstimatorKind::particle_restir, texels, rays, shading};
    };
    std::vector<LightingChoice> designs;
    for (const auto& [m, k] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{8, 4}, {4, 8}, {8, 8}, {4, 16}, {8, 16}})
        designs.push_back({LightSource::tree, m, 0, 1, pairwise, false, 1.0, particles(1, k)});
    designs.push_back({LightSource::tree, 8, 5, 1, pairwise, false, 1.0, particles(1, 4)});
    designs.push_back({LightSource::tree, 8, 0, 1, pairwise, false, 1.0, particles(2, 2)});
    designs.push_back({LightSource::tree, 32, 0, 1, pairwise, false, 1.0, particles(1, 4, PixelShading::resample)});
    if (space == "full")
        for (std::uint32_t m : x.candidates)
            for (std::uint32_t k : {2u, 4u, 8u, 16u})
                for (const auto& [nb, it] : x.spatial)
                    for (const BiasCorrection bc : x.corrections)
                        for (const PixelShading sh : {PixelShading::interpolate, PixelShading::resample})
                            designs.push_back({LightSource::tree, m, nb, it, bc, false, 1.0, particles(1, k, sh)});
    // voxel_cache (seed 004's radiance cache): light-tree rays from the
    // cells, the cosine lobe toward the camera (the billboards' normal).
    const auto voxels = [](std::uint32_t cells, std::uint32_t rays, VoxelBasis basis) {
        Design d{EstimatorKind::voxel_cache};
        d.cells = cells, d.cellRays = rays, d.basis = basis;
        return LightingChoice{LightSource::tree, 0, 0, 1, basic, false, 1.0, d};
    };
    designs.push_back(voxels(32, 8, VoxelBasis::camera));
    designs.push_back(voxels(64, 8, VoxelBasis::camera));
    if (space == "full")
        for (std::uint32_t cells : {32u, 64u, 128u, 256u})
            for (std::uint32_t rays : {4u, 8u, 16u, 32u})
                for (const VoxelBasis basis : {VoxelBasis::l1, VoxelBasis::camera})
                    if (!(rays == 8 && basis == VoxelBasis::camera && (cells == 32 || cells == 64)))
                        designs.push_back(voxels(cells, rays, basis));
    // particle_split (seed 004's hybrid compute): near lights, far rays each
    // kept by RIS among tree draws, the texels averaged by id.
    const auto split = [](std::uint32_t near, std::uint32_t far, std::uint32_t candidates, double history, std::uint32_t texels = 1) {
        Design d{EstimatorKind::particle_split};
        d.near = near, d.far = far, d.farCandidates = candidates, d.history = history, d.texels = texels;
        return LightingChoice{LightSource::tree, 0, 0, 1, basic, false, 1.0, d};
    };
    // The quick space's five: the cheapest, the twin's fastest under 10 ms
    // and under 16 ms at 100K (designs.md), and the first two with a longer
    // texel history (h = 0.9: about 19 frames averaged instead of 7, the
    // same kernels; its steady state moves tune's frame to 44).
    const std::vector<std::tuple<std::uint32_t, std::uint32_t, double>> quickSplits{
        {16, 8, 0.75}, {8, 4, 0.75}, {16, 16, 0.75}, {8, 4, 0.9}, {16, 8, 0.9}};
    for (const auto& [near, far, h] : quickSplits) designs.push_back(split(near, far, 8, h));
    if (space == "full")
        for (std::uint32_t near : {4u, 8u, 16u, 32u})
            for (std::uint32_t far : {4u, 8u, 16u})
                for (std::uint32_t c : {1u, 4u, 8u, 16u})
                    for (const double h : {0.0, 0.5, 0.75, 0.9})
                        if (!(c == 8 && std::find(quickSplits.begin(), quickSplits.end(), std::tuple{near, far, h}) != quickSplits.end()))
                            designs.push_back(split(near, far, c, h));
    // The long history of designs.md's answer: h = 0.95 averaging the far
    // light alone, from a running mean (steady after 51 frames, which moves
    // tune's frame there); a particle new to the view started from its near
    // lights' far means (far_prior) and every texel's shown blended with
    // them (far_share); the far history following the near set's changes
    // (far_handoff). The quick space holds designs.md's 100K answer and its
    // less biased form (far_share 64), the answer without them, the 1M
    // answer (4 candidates, antithetic texel points) and near 16, far 8;
    // the 100K answer and near 16, far 8 with far_handoff too.
    const auto longSplit = [&](std::uint32_t near, std::uint32_t far, std::uint32_t candidates, TexelPoint point,
                               std::uint32_t prior, std::uint32_t share, std::uint32_t farNew = 0, bool handoff = false) {
        LightingChoice c = split(near, far, candidates, 0.95);
        c.design.splitHistory = {point, HistoryStart::mean, HistoryOf::far, farNew, prior, share, handoff};
        return c;
    };
    using enum TexelPoint;
    designs.push_back(longSplit(8, 4, 8, centre, 0, 0));
    designs.push_back(longSplit(8, 4, 8, centre, 32, 64));
    designs.push_back(longSplit(8, 4, 8, centre, 32, 256));
    designs.push_back(longSplit(8, 4, 4, antithetic, 32, 256));
    designs.push_back(longSplit(16, 8, 8, centre, 32, 256));
    designs.push_back(longSplit(8, 4, 8, centre, 32, 256, 0, true));
    designs.push_back(longSplit(16, 8, 8, centre, 32, 256, 0, true));
    if (space == "full")  // the options across the answer's neighbourhood, 16 far rays for a new particle's texels, the hand-off
        for (std::uint32_t near : {8u, 16u})
            for (std::uint32_t far : {4u, 8u})
                for (std::uint32_t c : {4u, 8u})
                    for (const TexelPoint point : {centre, antithetic})
                        for (const auto& [prior, share] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{
                                 {0, 0}, {32, 0}, {32, 64}, {32, 256}, {32, 1024}})
                            for (const std::uint32_t farNew : {0u, 16u})
                                for (const bool handoff : {false, true})
                                    designs.push_back(longSplit(near, far, c, point, prior, share, farNew, handoff));
    out.insert(out.end(), designs.begin(), designs.end());
    // A grid point the quick space also lists is measured once: the first kept.
    std::set<std::string> labels;
    std::erase_if(out, [&](const LightingChoice& c) { return !labels.insert(c.label()).second; });
    return out;
}

/// "34 restir, 8 particle_restir, ...": the configurations of `space` per
/// design, counted from lightingChoices (--space's help).
std::string spaceSizes(const std::string& space) {
    const EstimatorKind kinds[] = {EstimatorKind::restir, EstimatorKind::particle_restir, EstimatorKind::voxel_cache,
                                   EstimatorKind::particle_split};
    std::vector<std::string> parts;
    const std::vector<LightingChoice> all = lightingChoices(space);
    for (const EstimatorKind k : kinds)
        parts.push_back(fmt::format("{} {}", std::count_if(all.begin(), all.end(), [&](const LightingChoice& c) { return c.design.estimator == k; }),
                                    enumName(k)));
    return fmt::format("{}, {}, {} and {}", parts[0], parts[1], parts[2], parts[3]);
}

/// The choices of the designs named by --designs (restir, particle_restir, voxel_cache, particle_split).
std::vector<LightingChoice> designChoices(const std::vector<LightingChoice>& all, const std::vector<std::string>& designs) {
    std::vector<LightingChoice> out;
    for (const std::string& d : designs) {
        EstimatorKind kind{};
        if (!parseEnum(d, kind) ||
            (kind != EstimatorKind::restir && kind != EstimatorKind::particle_restir && kind != EstimatorKind::voxel_cache &&
             kind != EstimatorKind::particle_split))
            throw InputError(fmt::format("command line --designs {}: expected restir, particle_restir, voxel_cache or particle_split", d));
        if (std::count(designs.begin(), designs.end(), d) > 1)
            throw InputError(fmt::format("command line --designs {}: named twice", d));
        for (const LightingChoice& c : all)
            if (c.design.estimator == kind) out.push_back(c);
    }
    return out;
}

/// FNV-1a over the text: the cache key of a measurement.
std::string cacheKey(const std::string& text) {
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
    return fmt::format("{:016x}", h);
}

/// The search's fixed inputs: this build, the scene file and its overrides.
struct TuneContext {
    const TuneArgs& args;
    const Settings* scene = nullptr;  ///< the scene with tune's overrides
    std::filesystem::path cache;
    std::string sceneText;  ///< version + scene file + overrides: every cache key starts with it
    std::vector<PixelWindow> crops;  ///< where the error is measured: one crop per stratum of the frame
    std::vector<std::string> references;           ///< one per crop
    std::vector<std::string> unshadowedReferences;  ///< --anatomy: the references with shading.visibility = false
    std::string referencesKey;  ///< the references' contents, hashed once: part of every error measurement's key
    std::uint32_t frame = 0;    ///< the measured frame
    std::uint32_t history = 0;  ///< frames before it: restir's steady state (steadyStateHistory), every configuration's least
    /// A configuration's own history where its steady state is longer
    /// (particle_split.history 0.9: 44 frames), by label (historyOf).
    std::map<std::string, std::uint32_t> longerHistories;
    std::uint32_t historyOf(const LightingChoice& o) const {
        const auto it = longerHistories.find(o.label());
        return it == longerHistories.end() ? history : it->second;
    }
    /// The longest: the frames every measurement's renders may need before the measured one.
    std::uint32_t longestHistory() const {
        std::uint32_t h = history;
        for (const auto& [label, frames] : longerHistories) h = std::max(h, frames);
        return h;
    }
    const StopSignal* stop = nullptr;  ///< SIGINT and SIGTERM: forwarded to the running measurement, then tune stops
    /// The history of the GPU-time counts: the frame counted needs its
    /// temporal pass running, not a saturated M cap. Measured on disk_100k at
    /// 1080p (tree M=8, 5 neighbours, pairwise, one BLAS of boxes refitted,
    /// fbef117): 7.324 ms predicted after 2 history frames, 7.322 after 20,
    /// in 13 s against 78 s; the error keeps the whole steady state.
    static constexpr std::uint32_t kCostHistory = 2;
    std::uint32_t costHistory() const { return std::min(history, kCostHistory); }
    CostCoefficients coefficients;  ///< what prices the counters
    std::size_t step = 0, steps = 0;
    /// Where the time goes, per kind of measurement (MeasureKind): seconds
    /// of the runs this time, and of the cached ones when they were run.
    struct Spent {
        double seconds = 0.0, cachedSeconds = 0.0;
        std::size_t runs = 0, cached = 0;
    };
    std::array<Spent, 3> spent{};
};

/// What a measurement is, for tune's account of its time.
enum class MeasureKind { reference, gpuTime, error };
constexpr std::array<const char*, 3> kMeasureKindNames = {"references", "GPU time (cost)", "error (bias)"};

/// A cached or fresh measurement read back by `read`: what it cannot read
/// (a truncated file, another command's output, JSON of another form) is
/// the user's error naming the file, which stays where it is.
template <class Read>
auto readMeasurement(const std::filesystem::path& file, const std::string& what, Read&& read) -> decltype(read()) {
    auto fail = [&](const char* why) {
        return InputError(fmt::format("tune: {} ({}) cannot be read: {}; delete it and run tune again to measure it again",
                                      displayPath(file), what, why));
    };
    try {
        return read();
    } catch (const InputError& e) {
        throw fail(e.what());
    } catch (const nlohmann::json::exception& e) {
        throw fail(e.what());
    }
}

/// Stops tune at a stop request, after its running measurement stopped:
/// every finished measurement stays in the cache, the same command resumes.
void stopTune(const TuneContext& t, int signal, const std::string& what) {
    removeStaleTemporaries(t.cache);  // a measurement stopped mid-write
    std::size_t kept = 0;
    for (const TuneContext::Spent& s : t.spent) kept += s.runs + s.cached;
    fmt::print(stderr, "tune: {}: stopped at {}; what was measured before it ({} of {}) stays in {}: the same command resumes from it\n",
               StopSignal::name(signal), what, kept, t.steps, displayPath(t.cache));
    throw Interrupted{signal};
}

/// Runs `argv` (this executable) unless `result` exists; its log beside it.
/// Its wall time is kept beside the result (RESULT.seconds), so that a
/// cached rerun still says what the measurement cost. A measurement refused
/// as the user's error (exit 1) is tune's user error, with the child's
/// message; a stop request is forwarded to it (stopTune).
void measure(TuneContext& t, MeasureKind kind, const std::vector<std::string>& argv, const std::filesystem::path& result,
             const std::string& what) {
    ++t.step;
    TuneContext::Spent& spent = t.spent[std::size_t(kind)];
    const std::filesystem::path secondsFile = result.string() + ".seconds";
    if (std::filesystem::exists(result)) {
        if (!t.args.quiet) fmt::print(stderr, "tune: [{}/{}] {} (cached)\n", t.step, t.steps, what);
        ++spent.cached;
        if (std::filesystem::exists(secondsFile))
            spent.cachedSeconds += parseNumber(readWholeFile(secondsFile.string(), "tune")).value_or(0.0);
        return;
    }
    if (t.stop && t.stop->pending()) stopTune(t, t.stop->pending(), what);
    if (!t.args.quiet) fmt::print(stderr, "tune: [{}/{}] {}\n", t.step, t.steps, what);
    const std::filesystem::path log = result.string() + ".log";
    const auto start = std::chrono::steady_clock::now();
    const int rc = runSelf(argv, log, t.stop);
    if (t.stop && t.stop->pending()) stopTune(t, t.stop->pending(), what);
    if (rc == 1) {  // the child's user error: "accretion: error: FILE: why"
        std::string why = lastLine(log);
        if (why.rfind("accretion: error: ", 0) == 0) why = why.substr(18);
        throw InputError(fmt::format("tune: {} failed: {} (log {})", what, why, displayPath(log)));
    }
    if (rc != 0 || !std::filesystem::exists(result))
        throw InternalError(fmt::format("tune: {} failed (exit {}): {} (log {})", what, rc, lastLine(log), log.string()));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    spent.seconds += seconds;
    ++spent.runs;
    writeFileAtomic(secondsFile.string(), fmt::format("{:.3f}", seconds));
}

/// Where tune's time went: per kind, the runs of this time and the cached ones' cost when run.
nlohmann::json spentJson(const TuneContext& t) {
    nlohmann::json j = nlohmann::json::object();
    for (std::size_t k = 0; k < t.spent.size(); ++k) {
        const TuneContext::Spent& s = t.spent[k];
        j[kMeasureKindNames[k]] = {{"runs", s.runs}, {"seconds", s.seconds}, {"cached", s.cached}, {"cached_seconds", s.cachedSeconds}};
    }
    return j;
}

std::vector<std::string> sceneArgv(const TuneContext& t, const std::string& command, const std::vector<std::string>& defines) {
    std::vector<std::string> a = {"/proc/self/exe", command, t.args.scene};
    for (const std::string& d : t.args.defines) a.insert(a.end(), {"-D", d});
    a.insert(a.end(), {"-D", "render.estimator=restir"});
    for (const std::string& d : defines) a.insert(a.end(), {"-D", d});
    if (t.args.threads > 0) a.insert(a.end(), {"--threads", std::to_string(t.args.threads)});
    return a;
}

/// Predicted GPU ms per pass of one configuration at the scene's
/// resolution: its counters (`accretion cost`, cached) priced with the calibration.
std::map<Pass, double> predictMs(TuneContext& t, const std::vector<std::string>& defines, const std::string& what) {
    std::string key = t.sceneText + fmt::format("\ncost frame {} history {}", t.frame, t.costHistory());
    for (const std::string& d : defines) key += "\n" + d;
    const std::filesystem::path prefix = t.cache / (cacheKey(key) + ".cost");
    std::vector<std::string> argv = sceneArgv(t, "cost", defines);
    argv.insert(argv.end(), {"--frames", fmt::format("{}:{}", t.frame, t.frame + 1), "--history", std::to_string(t.costHistory()), "--overhead", "0",
                             "--cluster-sizes", "", "--omm-levels", "", "--ser-keys", "hit", "-q", "-o", prefix.string() + ".json"});
    const std::string csv = prefix.string() + ".csv";
    measure(t, MeasureKind::gpuTime, argv, csv, "GPU time of " + what);
    std::map<Pass, double> ms;  // a pass's runs summed
    for (CostRow& r : readMeasurement(csv, "GPU time of " + what, [&] { return readCounterCsv(csv); })) {
        r.features[CostFeature::cold_work] =
            coldWork(r.features[CostFeature::rays], r.features[CostFeature::bytes], r.workingSetBytes, t.coefficients.cacheBytes);
        ms[r.pass.pass] += t.coefficients.predictMs(r.pass.pass, r.features);
    }
    return ms;
}

double total(const std::map<Pass, double>& ms) {
    double s = 0.0;
    for (const auto& [pass, v] : ms) s += v;
    return s;
}

/// What the bias runs could say of a configuration: a bias found, none
/// where one of --bias-bound would have shown, or too few seeds to tell.
enum class BiasVerdict { unbiased, biased, unknown };
constexpr const char* verdictName(BiasVerdict v) {
    return v == BiasVerdict::unbiased ? "unbiased" : v == BiasVerdict::biased ? "biased" : "unknown";
}
/// The verdict verdictName names, or nullopt.
std::optional<BiasVerdict> parseVerdict(const std::string& name) {
    for (const BiasVerdict v : {BiasVerdict::unbiased, BiasVerdict::biased, BiasVerdict::unknown})
        if (name == verdictName(v)) return v;
    return std::nullopt;
}

/// One lighting configuration's error: bias's row (relMSE of one frame less
/// the reference's noise, the mean signed error's t statistic, the energy loss, the
/// smallest energy bias its seeds detect 4 times in 5).
struct ErrorRow {
    double relMse = 0.0, t = 0.0, energyLossPct = 0.0, cpuSecondsPerFrame = 0.0, detectablePct = 0.0;
    double seedSd = 0.0, referenceMean = 0.0, referenceStderr = 0.0, zCritical = 0.0;  ///< bias's test: what more seeds would see
    double visibilitySharePct = NAN;  ///< --anatomy: the share of relMSE that every light visible removes
    std::uint32_t seeds = 0;
    BiasVerdict verdict = BiasVerdict::unknown;
    nlohmann::json reuse;  ///< bias's reuse of the measured frames, per pass (stats.json's counts.reuse)
    /// The share of `pass`'s offers kept, and of those on another particle (NaN where it did not run).
    std::pair<double, double> kept(Pass pass) const {
        const std::string key(passName(pass));  // bias writes each pass's counts under its name
        if (!reuse.is_object() || !reuse.contains(key)) return {std::nan(""), std::nan("")};
        const nlohmann::json& r = reuse.at(key);
        const double offered = r.at("offered").get<double>(), accepted = r.at("accepted").get<double>();
        const double other = r.at("outcomes").at("other_particle").get<double>();
        return {offered > 0.0 ? 100.0 * accepted / offered : std::nan(""), accepted > 0.0 ? 100.0 * other / accepted : std::nan("")};
    }
    bool biased() const { return verdict == BiasVerdict::biased; }
    /// "BIASED", "" (unbiased to the bound), "bias unknown (bound 9.9%)".
    std::string label() const {
        if (verdict == BiasVerdict::biased) return "BIASED";
        return verdict == BiasVerdict::unknown ? fmt::format("bias unknown (bound {:.2g}%)", detectablePct) : "";
    }
};

/// bias's JSON of one configuration as tune's row: an object of bias's form
/// for this estimator (a JSON of another form throws nlohmann's exception).
ErrorRow readErrorRow(const TuneContext& t, const std::string& spec, std::uint32_t seeds, const nlohmann::json& j) {
    if (j.at("command") != "bias" || j.at("rows").size() != 1 || j.at("rows").at(0).at("estimator") != spec)
        throw InputError(fmt::format("not bias's measurement of {}", spec));
    const nlohmann::json& r = j.at("rows").at(0);
    ErrorRow e;
    e.relMse = r.at("rel_mse").get<double>();
    e.t = r.at("t").get<double>();
    e.energyLossPct = r.at("energy_loss_pct").get<double>();
    e.cpuSecondsPerFrame = r.at("seconds_per_frame").get<double>();
    e.detectablePct = r.at("detectable_bias_pct").get<double>();
    e.seedSd = r.at("seed_sd").get<double>();
    e.referenceMean = j.at("reference_mean").get<double>();
    e.referenceStderr = j.at("reference_mean_stderr").get<double>();
    e.zCritical = j.at("z_critical").get<double>();
    e.seeds = seeds;
    if (j.contains("reuse") && j.at("reuse").contains(spec)) e.reuse = j.at("reuse").at(spec);
    if (!t.unshadowedReferences.empty()) e.visibilitySharePct = r.at("visibility_share_pct").get<double>();
    e.verdict = r.at("biased").get<bool>()                ? BiasVerdict::biased
              : e.detectablePct <= t.args.biasBoundPct ? BiasVerdict::unbiased
                                                        : BiasVerdict::unknown;
    return e;
}

ErrorRow measureErrorSeeds(TuneContext& t, const LightingChoice& o, std::uint32_t seeds) {
    std::string spec(enumName(o.design.estimator));  // restir's specs as before: their cache keys hold
    for (const std::string& d : o.defines())
        if (!d.starts_with("render.estimator=")) spec += ":" + d;
    const std::uint32_t history = t.historyOf(o);
    std::string key = t.sceneText + fmt::format("\nbias {} seeds {} frame {} history {} crop margin {}", spec, seeds, t.frame,
                                                history, t.args.cropMargin);
    key += t.referencesKey;
    const std::filesystem::path prefix = t.cache / (cacheKey(key) + ".bias");
    std::vector<std::string> argv = sceneArgv(t, "bias", {});
    for (const std::string& r : t.references) argv.insert(argv.end(), {"--reference", r});
    for (const std::string& r : t.unshadowedReferences) argv.insert(argv.end(), {"--unshadowed-reference", r});
    argv.insert(argv.end(), {"--crop-margin", std::to_string(t.args.cropMargin), "--estimators", spec, "--seeds",
                             std::to_string(seeds), "--frame", std::to_string(t.frame), "--history", std::to_string(history), "-q",
                             "-o", prefix.string()});
    const std::string file = prefix.string() + ".json", what = fmt::format("error of {} ({} seeds)", o.label(), seeds);
    measure(t, MeasureKind::error, argv, file, what);
    return readMeasurement(file, what, [&] { return readErrorRow(t, spec, seeds, nlohmann::json::parse(readWholeFile(file, "tune"))); });
}

/// The error again with the fewest seeds whose test would see a bias of
/// --bias-bound (Student's t: the bound falls faster than 1/sqrt(seeds)
/// while the degrees of freedom grow), up to --max-seeds; and again from
/// that measurement's spread while the verdict stays unknown and more
/// seeds would tell (a spread measured on few seeds can promise too few:
/// at 208e1f7 a configuration's 4 seeds asked for 5, whose bound was
/// 1.5%). Where no count up to --max-seeds would, the last measurement
/// stands, its verdict "unknown" with its bound.
ErrorRow measureMoreSeeds(TuneContext& t, const LightingChoice& o, const ErrorRow& first) {
    ErrorRow last = first;
    while (last.verdict == BiasVerdict::unknown && std::isfinite(last.detectablePct)) {
        // 10% spare on the variance: the seeds' spread is itself measured.
        const std::uint32_t needed = seedsToDetect(last.seedSd * std::sqrt(1.1), last.seeds, last.referenceStderr, last.zCritical,
                                                   t.args.biasBoundPct / 100.0 * last.referenceMean, t.args.maxSeeds);
        if (!needed) break;  // more than `last.seeds`, or none
        ++t.steps;           // a measurement the plan did not count
        last = measureErrorSeeds(t, o, needed);
    }
    return last;
}

/// --errors-from: a previous tune's error measurements (its JSON), reused
/// by configuration label so that a new calibration prices them without
/// the hours of bias runs they took. Only a run at the same operating point
/// may lend them: the same scene settings (the [gpu] section aside: it
/// changes the price, not the image), frame, history, crops, seeds and
/// bias bound; each configuration's verdict is the one that run left.
struct PreviousErrors {
    std::string file, version, coefficients;
    std::vector<std::string> references, unshadowedReferences;  ///< what its errors were measured against
    /// This search's configurations that run could not measure: their
    /// steady state does not fit before its frame (label -> frames needed).
    std::map<std::string, std::uint32_t> leftOut;
    std::map<std::string, ErrorRow> rows;  ///< by LightingChoice::label()

    const ErrorRow& row(const std::string& label) const {
        const auto it = rows.find(label);
        if (it == rows.end())
            throw InputError(fmt::format("{}: no error measurement of '{}': that run searched other configurations (its --space "
                                         "and --designs must cover this run's)", file, label));
        return it->second;
    }
};

/// The scene's settings as TOML without its [gpu] section: what an error
/// measurement depends on (the GPU settings change prices, not images).
std::string settingsWithoutGpu(const Settings& s) {
    const std::string toml = settingsToToml(s);
    const std::size_t gpu = toml.find("[gpu]\n");
    if (gpu == std::string::npos) return toml;
    const std::size_t next = toml.find("\n[", gpu + 1);
    return toml.substr(0, gpu) + (next == std::string::npos ? std::string() : toml.substr(next + 1));
}

/// Where two settings documents first differ: "[section] its line there, this run's here".
std::string firstDifference(const std::string& theirs, const std::string& ours) {
    std::istringstream a(theirs), b(ours);
    std::string section, x, y;
    for (;;) {
        const bool gotA = bool(std::getline(a, x)), gotB = bool(std::getline(b, y));
        if (!gotA && !gotB) return "the same settings";
        if (!gotA || !gotB || x != y)
            return fmt::format("{} '{}' there, '{}' here", section, gotA ? x : "(end)", gotB ? y : "(end)");
        if (x.starts_with("[")) section = x;
    }
}

/// A JSON number, NaN where the table wrote null (a value it had not).
double numberOrNan(const nlohmann::json& j, const char* key) {
    const nlohmann::json& v = j.at(key);
    return v.is_null() ? std::nan("") : v.get<double>();
}

/// --errors-from's file, read once: a tune run's JSON and its frame (InputError naming the file).
std::pair<nlohmann::json, std::uint32_t> readTuneJson(const std::string& file) {
    try {
        nlohmann::json j = nlohmann::json::parse(readWholeFile(file, "--errors-from"));
        if (!j.is_object() || j.value("command", "") != "tune")
            throw InputError(fmt::format("{}: not the JSON of a tune run (-o PREFIX writes PREFIX.json)", file));
        const std::uint32_t frame = j.at("frame").get<std::uint32_t>();
        return {std::move(j), frame};
    } catch (const nlohmann::json::exception& e) {
        throw InputError(fmt::format("{}: not the JSON of a tune run: {}", file, e.what()));
    }
}

/// --errors-from's errors, from its JSON j, checked to have measured this
/// run's operating point (InputError naming the file and what differs).
PreviousErrors readPreviousErrors(const TuneContext& t, const Settings& scene, const nlohmann::json& j) {
    const TuneArgs& a = t.args;
    PreviousErrors prev{a.errorsFrom};
    try {
        prev.version = j.at("version").get<std::string>();
        prev.coefficients = j.at("coefficients").get<std::string>();
        prev.references = j.at("references").get<std::vector<std::string>>();
        prev.unshadowedReferences = j.at("unshadowed_references").get<std::vector<std::string>>();
        const auto differs = [&](const char* what, const nlohmann::json& theirs, const nlohmann::json& ours) {
            if (theirs != ours)
                throw InputError(fmt::format("{}: measured at another operating point: {} {} there, {} here", a.errorsFrom, what,
                                             theirs.dump(), ours.dump()));
        };
        differs("frame", j.at("frame"), t.frame);
        differs("history_frames", j.at("history_frames"), t.history);
        differs("longer_histories", j.value("longer_histories", nlohmann::json::object()), nlohmann::json(t.longerHistories));
        differs("error_crops", j.at("error_crops"), a.errorCrops);
        differs("crop_size", j.at("crop_size"), a.cropSize);
        differs("crop_margin", j.at("crop_margin"), a.cropMargin);
        differs("crops", j.at("crops"), windowsJson(t.crops));
        differs("seeds", j.at("seeds"), a.seeds);
        differs("bias_bound_pct", j.at("bias_bound_pct"), a.biasBoundPct);
        differs("max_seeds", j.at("max_seeds"), a.maxSeeds);
        differs("anatomy", !j.at("unshadowed_references").empty(), a.anatomy);
        const std::string theirs = settingsWithoutGpu(parseScene(j.at("settings").get<std::string>(), a.errorsFrom + " settings"));
        if (const std::string ours = settingsWithoutGpu(scene); theirs != ours)
            throw InputError(fmt::format("{}: measured another scene: {}", a.errorsFrom, firstDifference(theirs, ours)));
        const nlohmann::json& reuse = j.at("reuse");
        for (const nlohmann::json& r : j.at("lighting")) {
            ErrorRow e;
            const std::string label = r.at("lighting").get<std::string>();
            e.relMse = r.at("rel_mse").get<double>();
            e.t = numberOrNan(r, r.contains("t") ? "t" : "z");  // runs before Student's t named the statistic z
            e.energyLossPct = numberOrNan(r, "energy_loss_pct");
            e.detectablePct = numberOrNan(r, "detectable_bias_pct");
            e.cpuSecondsPerFrame = numberOrNan(r, "cpu_s");
            e.visibilitySharePct = numberOrNan(r, "visibility_share_pct");
            e.seeds = r.at("seeds").get<std::uint32_t>();
            const std::optional<BiasVerdict> v = parseVerdict(r.at("bias_verdict").get<std::string>());
            if (!v)
                throw InputError(fmt::format("{}: '{}': bias_verdict '{}' is not unbiased, biased or unknown", a.errorsFrom, label,
                                             r.at("bias_verdict").get<std::string>()));
            e.verdict = *v;
            if (reuse.contains(label)) e.reuse = reuse.at(label);
            if (!prev.rows.emplace(label, std::move(e)).second)
                throw InputError(fmt::format("{}: '{}' measured twice", a.errorsFrom, label));
        }
    } catch (const nlohmann::json::exception& e) {
        throw InputError(fmt::format("{}: not the JSON of a tune run: {}", a.errorsFrom, e.what()));
    }
    return prev;
}

/// A reference of `frame`, crop `w` of the scene's view: its
/// size, data window and view (frame and scene-defining settings), its
/// pixels readable (InputError naming the file).
void checkReference(const Settings& scene, std::uint32_t frame, const std::string& file, const PixelWindow& w) {
    const RgbLayer image = readExrLayer(file, "Lr");
    if (image.width != scene.camera.width || image.height != scene.camera.height)
        throw InputError(fmt::format("{}: reference of a {}x{} view, the scene renders {}x{}", file, image.width, image.height,
                                     scene.camera.width, scene.camera.height));
    if (image.x0 != int(w.x0) || image.y0 != int(w.y0) || image.dataWidth != w.width() || image.dataHeight != w.height())
        throw InputError(fmt::format("{}: reference of pixels [{}, {}) x [{}, {}), its crop is [{}, {}) x [{}, {})", file, image.x0,
                                     std::int64_t(image.x0) + image.dataWidth, image.y0, std::int64_t(image.y0) + image.dataHeight,
                                     w.x0, w.x1, w.y0, w.y1));
    requireSceneView(readExrAttributes(file), file, FileRole::reference, scene, frame, false);
}

/// The references of the error measurements, one per crop: given, or
/// rendered once at the scene's resolution (exact up to 20K particles, else
/// split at --reference-spp), each crop alone, and cached.
std::vector<std::string> ensureReferences(TuneContext& t, std::size_t particles, bool visibility = true) {
    if (!t.args.references.empty() && visibility) return t.args.references;
    const bool exact = particles <= 20000;
    const std::string how = exact ? "exact" : fmt::format("split {} spp", t.args.referenceSpp);
    const std::string unshadowed = visibility ? "" : ", every light visible";
    std::vector<std::string> files;
    for (const PixelWindow& w : t.crops) {
        const std::string crop = fmt::format("[{},{},{},{}]", w.x0, w.x1, w.y0, w.y1);
        const std::filesystem::path file =
            t.cache / (cacheKey(t.sceneText + fmt::format("\nreference {} frame {} crop {}{}", how, t.frame, crop, unshadowed)) + ".ref.exr");
        std::vector<std::string> defines = {"render.crop=" + crop};
        if (!visibility) defines.push_back("shading.visibility=false");
        std::vector<std::string> argv = sceneArgv(t, "render", defines);
        // --resume: a reference stopped by a signal left its checkpoint; the
        // next tune continues it (its log says so: not --quiet).
        argv.insert(argv.end(), {"--estimator", exact ? "exact" : "split", "--frames", fmt::format("{}:{}", t.frame, t.frame + 1),
                                 "-o", file.string(), "--resume"});
        if (!exact) argv.insert(argv.end(), {"--spp", std::to_string(t.args.referenceSpp)});
        const std::string what = fmt::format("reference ({}, crop {}{})", how, crop, unshadowed);
        measure(t, MeasureKind::reference, argv, file, what);
        Settings rendered = *t.scene;
        rendered.shading.visibility = visibility;
        readMeasurement(file, what, [&] { checkReference(rendered, t.frame, file.string(), w); });
        files.push_back(file.string());
    }
    return files;
}

/// A measured configuration of the front's search.
struct ParetoPoint {
    LightingChoice lighting;
    double ms = 0.0;
    ErrorRow error;
    bool front = false;
};

/// Marks the Pareto front: no other point is both faster and better.
void markFront(std::vector<ParetoPoint>& points) {
    std::vector<std::size_t> order(points.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return points[a].ms != points[b].ms ? points[a].ms < points[b].ms : points[a].error.relMse < points[b].error.relMse;
    });
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i : order)
        if (points[i].error.relMse < best) {
            points[i].front = true;
            best = points[i].error.relMse;
        }
}

/// AxB of two whole numbers 1..16384 (--error-crops, --crop-size).
std::pair<std::uint32_t, std::uint32_t> parsePair(const std::string& text, const char* option, const char* example) {
    const auto x = text.find('x');
    const auto a = x == std::string::npos ? std::nullopt : parseUnsigned(text.substr(0, x));
    const auto b = x == std::string::npos ? std::nullopt : parseUnsigned(text.substr(x + 1));
    if (!a || !b || *a < 1 || *b < 1 || *a > 16384 || *b > 16384)
        throw InputError(fmt::format("command line {} {}: expected AxB, two whole numbers from 1 to 16384, e.g. {}", option, text, example));
    return {std::uint32_t(*a), std::uint32_t(*b)};
}

/// Where the error is measured, at the scene's resolution (never a
/// downscaled frame: upsampling and reuse radii are in pixels): the frame
/// cut into --error-crops strata, one --crop-size crop in each at a place
/// drawn once per stratum (a fixed hash of its index), so that the crops'
/// pixels are a stratified sample of the frame's. 1x1 with the frame's
/// size measures the whole frame.
std::vector<PixelWindow> errorCrops(const TuneArgs& a, const Settings& scene) {
    const auto [cols, rows] = parsePair(a.errorCrops, "--error-crops", "4x2");
    const auto [cw, ch] = parsePair(a.cropSize, "--crop-size", "192x108");
    const std::uint32_t W = scene.camera.width, H = scene.camera.height;
    const std::uint32_t sw = W / cols, sh = H / rows;
    if (cw > sw || ch > sh)
        throw InputError(fmt::format("command line --crop-size {}: a crop must fit its stratum, {}x{} for --error-crops {} of the "
                                     "{}x{} frame", a.cropSize, sw, sh, a.errorCrops, W, H));
    std::vector<PixelWindow> crops;
    for (std::uint32_t r = 0; r < rows; ++r)
        for (std::uint32_t c = 0; c < cols; ++c) {
            const std::uint64_t h = mix64(0x9e3779b97f4a7c15ull * (std::uint64_t(r) * cols + c + 1));
            const std::uint32_t x0 = c * sw + std::uint32_t((h & 0xffffffffu) % (sw - cw + 1));
            const std::uint32_t y0 = r * sh + std::uint32_t((h >> 32) % (sh - ch + 1));
            crops.push_back({x0, x0 + cw, y0, y0 + ch});
        }
    return crops;
}

/// The search's context with tune's numbers on the command line checked:
/// the budget, --max-error (before anything is made; the crops with the scene).
TuneContext checkTuneArgs(const TuneArgs& a) {
    if (!(a.budgetMs > 0.0) || !std::isfinite(a.budgetMs)) throw InputError("command line --budget-ms: expected a positive number of ms");
    if (a.maxError && (!(*a.maxError > 0.0) || !std::isfinite(*a.maxError)))
        throw InputError("command line --max-error: expected a positive relMSE");
    TuneContext t{a};
    return t;
}

/// The nearest existing folder at or above `p` ("." for a relative path
/// with none): what creating `p` would build on.
std::filesystem::path existingAncestor(std::filesystem::path p) {
    while (!p.empty() && !std::filesystem::exists(p)) p = p.parent_path();
    return p.empty() ? std::filesystem::path(".") : p;
}

/// -o: a prefix of file names (PREFIX.csv, .json, .png), not a folder, in
/// a folder that is or can be made (none of its parents a file).
void checkPrefix(const std::string& prefix, const char* option) {
    const std::filesystem::path p(prefix);
    const std::string name = p.filename().string();
    if (name.empty() || name == "." || name == ".." || std::filesystem::is_directory(p)) {
        std::string folder = prefix;
        while (folder.size() > 1 && folder.back() == '/') folder.pop_back();
        throw InputError(fmt::format("command line {} {}: expected a prefix of file names, not a folder ({}/NAME writes NAME.csv, "
                                     "NAME.json and NAME.png there)", option, prefix, folder.empty() ? "." : folder));
    }
    if (const std::filesystem::path up = existingAncestor(p.parent_path()); !std::filesystem::is_directory(up))
        throw InputError(fmt::format("command line {} {}: {} is a file, not a folder", option, prefix, displayPath(up)));
}

/// --cache: a folder, or one that can be made (none of its parents a file).
void checkFolder(const std::filesystem::path& folder, const char* option) {
    if (const std::filesystem::path up = existingAncestor(folder); !std::filesystem::is_directory(up))
        throw InputError(fmt::format("command line {} {}: {} is {}, not a folder", option, folder.string(), displayPath(up),
                                     up == folder ? "a file" : "a file above it"));
}

/// The search's context, its command line checked (checkTuneArgs): every
/// input checked (the scene's particle and camera files over the frames
/// tune renders, the given references) and its outputs and cache guarded
/// before anything is made; then the cache key, which covers the scene's
/// files by content, and the folders.
void prepareTune(TuneContext& t, const Settings& scene, const std::string& prefix) {
    const TuneArgs& a = t.args;
    t.scene = &scene;
    t.cache = a.cache.empty() ? std::filesystem::path("out") / "tune_cache" / scene.sceneName : std::filesystem::path(a.cache);
    checkFolder(t.cache, "--cache");
    checkPrefix(prefix, "-o");
    const std::uint32_t first = t.frame - t.longestHistory(), end = t.frame + 1;  // the histories and the measured frame
    OutputGuard guard = sceneInputs(scene, first, end);
    for (const std::string& r : a.references) guard.addInput(r);
    if (!a.errorsFrom.empty()) guard.addInput(a.errorsFrom);
    checkOutputs(guard, prefix, {".csv", ".json", ".png"}, "-o");
    for (std::size_t k = 0; k < a.references.size(); ++k) {
        if (!std::filesystem::is_regular_file(a.references[k]))
            throw InputError(fmt::format("command line --reference {}: no such file", a.references[k]));
        checkReference(scene, t.frame, a.references[k], t.crops[k]);
    }
    t.coefficients = CostCoefficients::forSetting(scene.gpu.coefficients);
    if (!t.coefficients.calibrated)
        throw InputError("tune: gpu.coefficients = \"uncalibrated\": tune prices with a calibration (the committed one by default)");
    // The cache key: this build, the scene, its overrides and the files it
    // reads by content (but the calibration, which prices the cached
    // counters here, not in them).
    t.sceneText = std::string(version()) + "\n" + readWholeFile(a.scene, "tune");
    for (const std::string& d : a.defines)
        if (d.rfind("gpu.coefficients", 0) != 0) t.sceneText += "\n-D " + d;
    t.sceneText += "\n-D render.estimator=restir";  // sceneArgv's
    std::vector<std::filesystem::path> inputs = ParticleSource(scene).checkFiles(first, end);
    if (!scene.camera.file.empty()) inputs.emplace_back(scene.camera.file);
    for (const std::filesystem::path& f : inputs) t.sceneText += "\ninput " + cacheKey(readWholeFile(f.string(), "tune"));
    std::filesystem::create_directories(t.cache);
    if (auto dir = std::filesystem::path(prefix).parent_path(); !dir.empty()) std::filesystem::create_directories(dir);
}

/// A geometry choice priced: its predicted GPU ms per pass at the scene's lighting.
struct PricedGeometry {
    GeometryChoice choice;
    std::map<Pass, double> ms;
};

/// The recommendation: under the budget (and --max-error), never biased
/// unless allowed; a configuration whose seeds could see a bias of
/// --bias-bound before one they could not (which is recommended only with
/// its label, "bias unknown (bound X%)"); then the lowest error, or with
/// --max-error the fastest that meets it.
const ParetoPoint* recommend(const TuneArgs& a, const std::vector<ParetoPoint>& points) {
    const ParetoPoint* best = nullptr;
    auto better = [&](const ParetoPoint& p, const ParetoPoint& q) {
        const bool pk = p.error.verdict != BiasVerdict::unknown, qk = q.error.verdict != BiasVerdict::unknown;
        if (pk != qk) return pk;
        return a.maxError ? p.ms < q.ms : p.error.relMse < q.error.relMse;
    };
    for (const ParetoPoint& p : points) {
        if (p.ms > a.budgetMs || (p.error.biased() && !a.allowBiased)) continue;
        if (a.maxError && p.error.relMse > *a.maxError) continue;
        if (!best || better(p, *best)) best = &p;
    }
    return best;
}

/// Seeds where the recommendation needs them: in the order the
/// recommendation ranks the eligible configurations (under the budget and
/// --max-error, not found biased; by error, or by time with --max-error), each
/// whose bias is unknown is measured again with the seeds that would see
/// --bias-bound (measureMoreSeeds), until one is verified unbiased: nothing
/// ranked after it can be recommended before it, so its seeds would be spent
/// for nothing. Each configuration gets more seeds at most once; the others
/// keep their "bias unknown (bound X%)".
void verifyCandidates(TuneContext& t, std::vector<ParetoPoint>& points) {
    const TuneArgs& a = t.args;
    std::vector<bool> tried(points.size(), false);
    for (;;) {
        std::vector<std::size_t> order;
        for (std::size_t k = 0; k < points.size(); ++k) {
            const ParetoPoint& p = points[k];
            if (p.ms > a.budgetMs || (p.error.biased() && !a.allowBiased)) continue;
            if (a.maxError && p.error.relMse > *a.maxError) continue;
            order.push_back(k);
        }
        std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
            return a.maxError ? points[i].ms < points[j].ms : points[i].error.relMse < points[j].error.relMse;
        });
        const auto next = std::find_if(order.begin(), order.end(), [&](std::size_t k) {
            return points[k].error.verdict == BiasVerdict::unbiased || (points[k].error.verdict == BiasVerdict::unknown && !tried[k]);
        });
        if (next == order.end() || points[*next].error.verdict == BiasVerdict::unbiased) return;
        tried[*next] = true;
        points[*next].error = measureMoreSeeds(t, points[*next].lighting, points[*next].error);
    }
}

/// The lighting choices on the chosen geometry: error on the CPU (--seeds,
/// then more where the recommendation needs them), GPU time priced; the
/// Pareto front marked, sorted by time.
std::vector<ParetoPoint> measureLighting(TuneContext& t, const GeometryChoice& chosen, const std::vector<LightingChoice>& lighting,
                                         const PreviousErrors* previous) {
    std::vector<ParetoPoint> points;
    for (const LightingChoice& l : lighting) {
        ParetoPoint p{l};
        std::vector<std::string> defines = chosen.defines();
        const std::vector<std::string> own = l.defines();
        defines.insert(defines.end(), own.begin(), own.end());
        p.ms = total(predictMs(t, defines, l.label()));
        p.error = previous ? previous->row(l.label()) : measureErrorSeeds(t, l, t.args.seeds);
        points.push_back(std::move(p));
    }
    if (!previous) verifyCandidates(t, points);  // --errors-from: the verdicts that run left
    markFront(points);
    std::sort(points.begin(), points.end(), [](const ParetoPoint& p, const ParetoPoint& q) { return p.ms < q.ms; });
    return points;
}

/// What tune found, as its report, CSV, JSON and plot read it.
struct TuneResult {
    std::vector<PricedGeometry> geometry;
    const PricedGeometry* chosen = nullptr;     ///< the fastest
    const PricedGeometry* triangles = nullptr;  ///< the fastest of triangles (not boxes)
    std::vector<ParetoPoint> points;
    const ParetoPoint* best = nullptr;
    std::optional<PreviousErrors> previous;  ///< --errors-from
};

Table geometryTable(const TuneResult& r) {
    Table gt({{"geometry", "geometry (the image does not depend on it)", -44}, {"build_ms", "build ms", 9, "{:.3f}", "{:.6g}"},
              {"gbuffer_ms", "G-buffer", 9, "{:.3f}", "{:.6g}"}, {"shadow_ms", "shadow", 9, "{:.3f}", "{:.6g}"},
              {"frame_ms", "frame ms", 9, "{:.3f}", "{:.6g}"}});
    const auto of = [](const std::map<Pass, double>& ms, Pass p) { return ms.count(p) ? ms.at(p) : 0.0; };
    for (const auto& [g, ms] : r.geometry)
        gt.add({g.label(), of(ms, Pass::buildClusters), of(ms, Pass::traceGBuffer), of(ms, Pass::traceShadowRays), total(ms)});
    return gt;
}

Table lightingTable(const TuneArgs& a, const TuneResult& r) {
    Table lt({{"lighting", "lighting (on the chosen geometry)", -36}, {"gpu_ms", "GPU ms", 9, "{:.3f}", "{:.6g}"},
              {"rel_mse", "relMSE", 10, "{:.4g}", "{:.6g}"}, {"t", "bias t", 7, "{:.1f}", "{:.5g}"},
              {"energy_loss_pct", "loss %", 7, "{:.1f}", "{:.5g}"}, {"detectable_bias_pct", "bound %", 8, "{:.2g}", "{:.5g}"},
              {"seeds", "seeds", 6}, {"temporal_kept_pct", "temp kept%", 10, "{:.0f}", "{:.4g}"},
              {"spatial_kept_pct", "spat kept%", 10, "{:.0f}", "{:.4g}"}, {"spatial_other_particle_pct", "of them other%", 14, "{:.0f}", "{:.4g}"},
              {"visibility_share_pct", "vis share%", 10, "{:.0f}", "{:.4g}"},
              {"light_selection_share_pct", "sel share%", 10, "{:.0f}", "{:.4g}"},
              {"cpu_s", "CPU s", 7, "{:.2f}", "{:.5g}"},
              {"biased", "", 0, "{}", "{}", false}, {"bias_verdict", "", 0, "{}", "{}", false}, {"front", "", 0, "{}", "{}", false},
              {"", "", 0, "{}", "{}", true, "  "}});
    for (const ParetoPoint& p : r.points) {
        const std::string bias = p.error.label();
        const double temporalKept = p.error.kept(Pass::temporalResampling).first;
        // Spatial reuse: restir's screen disc, or particle_restir's world neighbours.
        auto [spatialKept, spatialOther] = p.error.kept(Pass::spatialResampling);
        if (std::isnan(spatialKept)) std::tie(spatialKept, spatialOther) = p.error.kept(Pass::resampleWorldNeighbours);
        lt.add({p.lighting.label(), p.ms, p.error.relMse, p.error.t, p.error.energyLossPct, p.error.detectablePct,
                std::uint64_t(p.error.seeds), temporalKept, spatialKept, spatialOther, p.error.visibilitySharePct,
                100.0 - p.error.visibilitySharePct,
                p.error.cpuSecondsPerFrame, p.error.biased(), std::string(verdictName(p.error.verdict)),
                p.front,
                std::string(p.front ? "front" : "") + (bias.empty() ? "" : " " + bias) + (&p == r.best ? " <- recommended" : "")});
    }
    return lt;
}

/// Per design (restir, particle_restir, voxel_cache, particle_split), its point of lowest relMSE under
/// the budget (biased points only with --allow-biased).
std::map<std::string, const ParetoPoint*> bestPerDesign(const TuneArgs& a, const TuneResult& r) {
    std::map<std::string, const ParetoPoint*> best;
    for (const ParetoPoint& p : r.points) {
        if (p.ms > a.budgetMs || (p.error.biased() && !a.allowBiased)) continue;
        const ParetoPoint*& b = best[std::string(enumName(p.lighting.design.estimator))];
        if (!b || p.error.relMse < b->error.relMse) b = &p;
    }
    return best;
}

/// The tables and the verdict on stdout.
void printTune(const TuneArgs& a, const Settings& scene, const TuneContext& t, const TuneResult& r, const Table& gt, const Table& lt) {
    fmt::print("{}\n{}", gt.console(), lt.console());
    fmt::print("error measured at frame {} after {} history frames (restir's steady state: temporal reuse to its M cap of {:g}), "
               "at {}x{} on {} crops of {} ({} strata; restir with {} pixels of margin); GPU time counted after {}\n",
               t.frame, t.history, scene.restir.m_cap, scene.camera.width, scene.camera.height, t.crops.size(), a.cropSize,
               a.errorCrops, a.cropMargin, t.costHistory());
    for (const auto& [label, frames] : t.longerHistories)
        fmt::print("  {}: after {} history frames (its own steady state)\n", label, frames);
    const GeometryChoice& chosen = r.chosen->choice;
    fmt::print("geometry: {} ({:.3f} ms predicted at {}x{}, the scene's lighting)\nGPU time: {}\n", chosen.label(),
               total(r.chosen->ms), scene.camera.width, scene.camera.height, t.coefficients.source);
    if (r.previous)
        fmt::print("error: read from {} (accretion {}, priced there by {}); no error measured, each verdict as that run left it\n",
                   r.previous->file, r.previous->version, r.previous->coefficients);
    if (r.previous)
        for (const auto& [label, frames] : r.previous->leftOut)
            fmt::print("  left out: {} needs {} history frames, and {} measured frame {}\n", label, frames, r.previous->file, t.frame);
    // Procedural boxes beat triangles only where traversal is software: on
    // RT cores every box entered calls the intersection program on the SM
    // (docs/layouts.md). Name the fastest triangle layout beside them.
    if (chosen.layout == AccelLayout::aabbs && r.triangles->choice.layout != AccelLayout::aabbs)
        fmt::print("on a GPU with RT cores prefer {} ({:+.3f} ms here): boxes win only where traversal runs in software\n",
                   r.triangles->choice.label(), total(r.triangles->ms) - total(r.chosen->ms));
    if (const ParetoPoint* best = r.best)
        fmt::print("recommended under {:g} ms{}: {} + {}: {:.3f} GPU ms predicted, relMSE {:.4g} ({} seeds), {}\n", a.budgetMs,
                   a.maxError ? fmt::format(" and relMSE {:g}", *a.maxError) : "", chosen.label(), best->lighting.label(), best->ms,
                   best->error.relMse, best->error.seeds,
                   best->error.label().empty() ? fmt::format("unbiased to {:.2g}%", best->error.detectablePct) : best->error.label());
    // Which design and why: each design's lowest error under the budget
    // (biased ones aside unless allowed), and how many times the
    // recommendation's error and GPU time it is.
    for (const auto& [design, p] : bestPerDesign(a, r))
        fmt::print("  best {} under {:g} ms: {} at {:.3f} ms, relMSE {:.4g}{}\n", design, a.budgetMs, p->lighting.label(), p->ms,
                   p->error.relMse,
                   p == r.best ? std::string(" (recommended)")
                   : r.best    ? fmt::format(" ({:.3g}x the recommendation's error in {:.2f}x its time)", p->error.relMse / r.best->error.relMse,
                                             p->ms / r.best->ms)
                               : std::string());
    if (!r.best)
        fmt::print("no {}configuration is under {:g} ms{}\n", a.allowBiased ? "" : "unbiased ", a.budgetMs,
                   a.maxError ? fmt::format(" with relMSE <= {:g}", *a.maxError) : "");
    std::string spent;
    double total = 0.0;
    for (std::size_t k = 0; k < t.spent.size(); ++k) {
        const TuneContext::Spent& x = t.spent[k];
        total += x.seconds + x.cachedSeconds;
        spent += fmt::format("{}{} {:.0f} s ({} run{}, {} cached: {:.0f} s when run)", spent.empty() ? "" : "; ", kMeasureKindNames[k],
                             x.seconds + x.cachedSeconds, x.runs, x.runs == 1 ? "" : "s", x.cached, x.cachedSeconds);
    }
    fmt::print("time: {:.0f} s of measurements: {}\n", total, spent);
    std::fflush(stdout);
}

/// PREFIX.json: what made the search and what it found.
void writeTuneJson(const std::string& prefix, const TuneArgs& a, const Settings& scene, const TuneContext& t, const TuneResult& r,
                   const Table& gt, const Table& lt) {
    const GeometryChoice& chosen = r.chosen->choice;
    nlohmann::json recommended = nullptr;
    if (const ParetoPoint* best = r.best) {
        std::vector<std::string> defines = chosen.defines();
        const std::vector<std::string> own = best->lighting.defines();
        defines.insert(defines.end(), own.begin(), own.end());
        recommended = {{"geometry", chosen.label()}, {"lighting", best->lighting.label()}, {"defines", defines}, {"gpu_ms", best->ms},
                       {"rel_mse", best->error.relMse}, {"biased", best->error.biased()},
                       {"bias_verdict", verdictName(best->error.verdict)}, {"detectable_bias_pct", best->error.detectablePct},
                       {"seeds", best->error.seeds}, {"design", enumName(best->lighting.design.estimator)}};
    }
    nlohmann::json designs = nlohmann::json::object();  // each design's best under the budget
    for (const auto& [design, p] : bestPerDesign(a, r))
        designs[design] = {{"lighting", p->lighting.label()}, {"gpu_ms", p->ms}, {"rel_mse", p->error.relMse},
                           {"error_vs_recommended", r.best ? nlohmann::json(p->error.relMse / r.best->error.relMse) : nlohmann::json()}};
    nlohmann::json reuse = nlohmann::json::object();  // per lighting configuration, per pass: the offers by outcome
    for (const ParetoPoint& p : r.points)
        if (!p.error.reuse.is_null()) reuse[p.lighting.label()] = p.error.reuse;
    writeJson(prefix + ".json", {{"version", std::string(version())}, {"command", "tune"}, {"scene", scene.scenePath},
                                 {"defines", a.defines}, {"settings", settingsToToml(scene)}, {"seed", scene.render.seed},
                                 {"budget_ms", a.budgetMs}, {"bias_bound_pct", a.biasBoundPct}, {"max_seeds", a.maxSeeds}, {"max_error", a.maxError ? nlohmann::json(*a.maxError) : nlohmann::json()},
                                 {"seeds", a.seeds}, {"frame", t.frame}, {"history_frames", t.history}, {"longer_histories", t.longerHistories}, {"cost_history_frames", t.costHistory()}, {"error_crops", a.errorCrops}, {"crop_size", a.cropSize},
                                 {"crop_margin", a.cropMargin}, {"crops", windowsJson(t.crops)}, {"references", t.references},
                                 {"unshadowed_references", t.unshadowedReferences},
                                 {"space", a.space}, {"coefficients", t.coefficients.source}, {"geometry", gt.json()},
                                 {"fastest_triangle_geometry", r.triangles->choice.label()}, {"chosen_geometry", chosen.label()},
                                 {"lighting", lt.json()}, {"reuse", reuse}, {"recommended", recommended}, {"best_per_design", designs}, {"time", spentJson(t)},
                                 {"errors_from", r.previous ? nlohmann::json{{"file", r.previous->file}, {"version", r.previous->version},
                                                                             {"coefficients", r.previous->coefficients},
                                                                             {"left_out", r.previous->leftOut}}
                                                            : nlohmann::json()}});
}

/// PREFIX.png: the configurations' error against predicted GPU ms by bias
/// verdict, the front and the budget; the columns found by their keys in `lt`.
void plotTune(const std::string& prefix, const TuneArgs& a, const Settings& scene, std::size_t particles, const TuneResult& r,
              const Table& lt) {
    const std::string csv = gnuplotQuote(prefix + ".csv");
    const ParetoPoint* best = r.best;
    double maxMs = a.budgetMs;
    for (const ParetoPoint& p : r.points) maxMs = std::max(maxMs, p.ms);
    const std::size_t ms = lt.csvColumn("gpu_ms"), err = lt.csvColumn("rel_mse"), verdict = lt.csvColumn("bias_verdict"),
                      front = lt.csvColumn("front");
    auto points = [&](const char* which, const char* style, const char* title) {
        return fmt::format("{} skip 1 using {}:(strcol({}) eq '{}' ? ${} : NaN) with points {} title '{}'", csv, ms, verdict, which, err,
                           style, title);
    };
    const std::string script = fmt::format(
        "set datafile separator ','\nset logscale y\nset grid\nset key top right\nset xrange [0:{7}]\n"
        "set title {0}\nset xlabel 'predicted GPU ms per frame ({1}; calibrated cost model)'\nset ylabel 'relMSE on {2} ({3}+ seeds)'\n"
        "set arrow from {4},graph 0 to {4},graph 1 nohead dt 2 lc rgb 'gray40'\n"
        "set label 'budget' at {4},graph 0.05 right offset -0.5,0 tc rgb 'gray40'\n{6}"
        "plot {8}, {9}, {10}, {5} skip 1 using {11}:(${12} != 0 ? ${13} : NaN) with points pt 6 ps 2 lc rgb 'blue' title 'Pareto front'\n",
        gnuplotQuote(fmt::format("{} ({} particles) at {}x{}: budget {:g} ms", scene.sceneName, particles,
                                 scene.camera.width, scene.camera.height, a.budgetMs)),
        r.chosen->choice.label(), fmt::format("{} crops of {}", a.errorCrops, a.cropSize), a.seeds, a.budgetMs, csv,
        best ? fmt::format("set label 'recommended' at {},{} point pt 3 ps 3 lc rgb 'dark-green' offset 1,1 tc rgb 'dark-green'\n", best->ms,
                           best->error.relMse)
             : std::string(),
        1.08 * maxMs, points("unbiased", "pt 7 ps 1.3 lc rgb 'dark-green'", fmt::format("unbiased to {:g}%", a.biasBoundPct).c_str()),
        points("unknown", "pt 7 lc rgb 'gray60'", "bias unknown"),
        points("biased", "pt 2 ps 1.5 lc rgb 'red'", "biased (|t| above its critical value, 99.9%)"), ms, front, err);
    plotPng(prefix + ".png", script);
}

/// The frames before the measured one that bring configuration `o` to its
/// own steady state (steadyStateHistory of the scene with its settings).
std::uint32_t steadyHistoryOf(const TuneArgs& a, const LightingChoice& o) {
    SceneArgs with = a;
    with.defines.push_back("render.estimator=restir");  // as its measurements' child processes (sceneArgv)
    for (const std::string& d : o.defines()) with.defines.push_back(d);
    return steadyStateHistory(loadSceneArgs(with, {}));
}

void runTune(const TuneArgs& a) {
    const Settings scene = loadSceneArgs(a, {{"render.estimator", "tune (restir)", [](Settings& s) { s.render.estimator = EstimatorKind::restir; }}});
    requireWholeImage(scene, "tune");
    TuneContext t = checkTuneArgs(a);
    // The engine's operating point: the frame after the history that brings
    // temporal reuse to its M cap, and each configuration whose own steady
    // state is longer (a texel history) to its own.
    t.history = steadyStateHistory(scene);
    const std::vector<GeometryChoice> geometry = geometryChoices(scene);
    // --errors-from: that run's frame unless --frame says otherwise (then
    // checked against it); this search's configurations whose steady state
    // does not fit before it are left out, since that run could not have
    // measured them (a space that grew since).
    std::optional<std::pair<nlohmann::json, std::uint32_t>> previousRun;
    if (!a.errorsFrom.empty()) previousRun = readTuneJson(a.errorsFrom);
    const bool previousFrame = previousRun && !a.frame;
    std::map<std::string, std::uint32_t> leftOut;
    std::vector<LightingChoice> lighting;
    for (const LightingChoice& o : designChoices(lightingChoices(a.space), a.designs)) {
        const std::uint32_t h = steadyHistoryOf(a, o);
        if (previousFrame && h > previousRun->second) {
            leftOut[o.label()] = h;
            continue;
        }
        if (h > t.history) t.longerHistories[o.label()] = h;
        lighting.push_back(o);
    }
    const std::uint32_t needed = t.longestHistory();
    const std::uint64_t frame = a.frame ? *a.frame : previousFrame ? previousRun->second : std::uint64_t(scene.render.frame_start) + needed;
    if (frame >= 0xffffffffull)  // tune renders frame + 1's end
        throw InputError(fmt::format("command line --frame {}: expected a frame from {} to 4294967294", frame, needed));
    t.frame = std::uint32_t(frame);
    if (t.history > t.frame)  // tune has no --history: its frame must come after the whole history
        throw InputError(fmt::format("command line --frame {}: tune measures restir at steady state, after {} history frames "
                                     "(temporal reuse to its M cap of {:g}, at least 8): measure frame {} or later",
                                     t.frame, t.history, scene.restir.m_cap, t.history));
    if (needed > t.frame) {  // a longer history than restir's: name the (first) longest
        const auto longest = std::max_element(t.longerHistories.begin(), t.longerHistories.end(),
                                              [](const auto& x, const auto& y) { return x.second < y.second; });
        throw InputError(fmt::format("command line --frame {}: {} needs {} history frames (its steady state), and frames start at 0: "
                                     "measure frame {} or later, or leave it out of --space/--designs",
                                     t.frame, longest->first, needed, needed));
    }
    const std::string prefix = a.out.empty() ? "out/" + scene.sceneName + ".tune" : a.out;
    t.crops = errorCrops(a, scene);
    if (!a.references.empty() && a.references.size() != t.crops.size())  // before anything is made
        throw InputError(fmt::format("command line --reference: {} given, one per crop of --error-crops {} ({})", a.references.size(),
                                     a.errorCrops, t.crops.size()));
    // --errors-from: read and checked before anything is made.
    std::optional<PreviousErrors> previous;
    if (previousRun) {
        previous = readPreviousErrors(t, scene, previousRun->first);
        previous->leftOut = std::move(leftOut);
    }
    prepareTune(t, scene, prefix);
    const OutputLock lock(t.cache / "tune.lock");  // one tune per cache: a measurement is made once
    removeStaleTemporaries(t.cache);                 // what a measurement killed mid-write left
    const StopSignal stop;                           // forwarded to the running measurement (measure)
    t.stop = &stop;
    TuneResult r;
    const std::size_t particles = ParticleSource(scene).frame(t.frame).size();
    if (previous) {  // the errors of a previous run: no reference, no bias run; its references recorded as its errors' own
        t.references = previous->references;
        t.unshadowedReferences = previous->unshadowedReferences;
        r.previous = std::move(previous);
        t.steps = geometry.size() + lighting.size();
    } else {
        t.steps = geometry.size() + 2 * lighting.size() + (a.references.empty() ? t.crops.size() : 0) + (a.anatomy ? t.crops.size() : 0);
        t.references = ensureReferences(t, particles);
        if (a.anatomy) t.unshadowedReferences = ensureReferences(t, particles, false);
        for (const std::string& ref : t.references) t.referencesKey += "\nreference " + cacheKey(readWholeFile(ref, "tune"));
        for (const std::string& ref : t.unshadowedReferences) t.referencesKey += "\nunshadowed " + cacheKey(readWholeFile(ref, "tune"));
    }

    // Geometry: the same image whatever it is; the fastest predicted frame.
    for (const GeometryChoice& g : geometry) r.geometry.push_back({g, predictMs(t, g.defines(), g.label())});
    const auto faster = [](const PricedGeometry& p, const PricedGeometry& q) { return total(p.ms) < total(q.ms); };
    r.chosen = &*std::min_element(r.geometry.begin(), r.geometry.end(), faster);
    r.triangles = &*std::min_element(r.geometry.begin(), r.geometry.end(), [&](const PricedGeometry& p, const PricedGeometry& q) {
        const bool pb = p.choice.layout == AccelLayout::aabbs, qb = q.choice.layout == AccelLayout::aabbs;
        return pb != qb ? qb : faster(p, q);
    });
    // Lighting: error on the CPU, GPU time on the chosen geometry.
    r.points = measureLighting(t, r.chosen->choice, lighting, r.previous ? &*r.previous : nullptr);
    r.best = recommend(a, r.points);

    const Table gt = geometryTable(r), lt = lightingTable(a, r);
    printTune(a, scene, t, r, gt, lt);
    writeFileAtomic(prefix + ".csv", lt.csv());
    writeTuneJson(prefix, a, scene, t, r, gt, lt);
    plotTune(prefix, a, scene, particles, r, lt);
    fmt::print("tune: {}.csv, {}.json, {}.png (cache {})\n", prefix, prefix, prefix, t.cache.string());
}

}  // namespace

void addTuneCommand(CLI::App& app) {
    auto args = std::make_shared<TuneArgs>();
    CLI::App* cmd = app.add_subcommand(
        "tune", "Search the GPU frame's configurations: predicted GPU ms (calibrated cost model) against error (CPU), Pareto front, "
                "the best under a budget");
    addSceneOptions(cmd, *args, "");
    cmd->remove_option(cmd->get_option("--frames"));  // tune measures one frame: --frame
    cmd->add_option("--budget-ms", args->budgetMs, "GPU time budget of a frame, ms (the cost model's prediction)")->required();
    cmd->add_option("--max-error", args->maxError, "Recommend the fastest configuration with relMSE at most this (on the crops)");
    cmd->add_option("--seeds", args->seeds, "Seeds of every lighting configuration's first error and bias measurement (more where they decide the recommendation, up to --max-seeds)")->check(CLI::Range(2u, 100000u));
    cmd->add_option("--frame", args->frame,
                    "The measured frame, after the history that brings temporal reuse to steady state (ceil(restir.m_cap) "
                    "frames, at least 8) and each configuration with a longer one to its own (a texel history: 44 frames at "
                    "particle_split.history 0.9); default: render.frame_start + the longest");
    cmd->add_option("--error-crops", args->errorCrops,
                    "Where the error is measured, at the scene's resolution: the frame cut into COLUMNSxROWS strata, one crop "
                    "each (1x1 with --crop-size the frame's: the whole frame)");
    cmd->add_option("--crop-size", args->cropSize, "Each crop's size in pixels, WIDTHxHEIGHT");
    cmd->add_option("--crop-margin", args->cropMargin, "The pixels around each crop that restir renders for its reuse (restir.crop_margin)")
        ->check(CLI::Range(0u, 16384u));
    cmd->add_option("--designs", args->designs, "the designs searched: restir (per pixel), particle_restir (per particle texel), voxel_cache (world cells), particle_split (per particle texel: near lights and light-tree rays); all by default")
        ->delimiter(',');
    cmd->add_option("--space", args->space,
                    fmt::format("quick ({} configurations) or full ({}: hours)", spaceSizes("quick"), spaceSizes("full")));
    CLI::Option* errorsFrom = cmd->add_option(
        "--errors-from", args->errorsFrom,
        "A previous tune's JSON at the same operating point (scene, frame, crops, seeds): its error measurements and bias "
        "verdicts are reused, by configuration, and only the GPU time is priced (a new calibration in minutes, not hours)");
    cmd->add_option("--reference", args->references,
                    "Reference EXRs of --frame, one per crop in stratum order, row by row (default: rendered once, exact up to 20K "
                    "particles, else split)")
        ->allow_extra_args(false)
        ->excludes(errorsFrom);
    cmd->add_option("--reference-spp", args->referenceSpp, "split's samples per pixel for the rendered reference")
        ->check(CLI::Range(1u, 1u << 20));
    cmd->add_option("--cache", args->cache, "Folder of cached measurements (default out/tune_cache/<scene>)");
    cmd->add_flag("--allow-biased", args->allowBiased, "Biased configurations may be recommended");
    cmd->add_flag("--anatomy", args->anatomy,
                  "Also measure each configuration with every light visible against a reference without visibility (rendered "
                  "once): visibility's share of its error (twice the error measurements)");
    cmd->add_option("--bias-bound", args->biasBoundPct,
                    "Energy bias (%) a configuration's seeds must be able to see for it to count as unbiased: tune adds "
                    "seeds where such a bias could hide, up to --max-seeds, else labels it \"bias unknown (bound X%)\"")
        ->check(finiteIn(1e-6, 100.0));
    cmd->add_option("--max-seeds", args->maxSeeds, "The most seeds tune spends on one configuration's bias verdict")
        ->check(CLI::Range(2u, 100000u));
    cmd->add_option("-o,--output", args->out, "Output prefix (default out/<scene>.tune): .csv, .json, .png");
    cmd->callback([args] { runTune(*args); });
}

}  // namespace accretion::cmd
