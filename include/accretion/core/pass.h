#pragma once
// The passes of a frame, as one table (docs/MODEL.md section 5 and 6). Every
// timer, counter record, report row, cost coefficient and GPU timing is
// keyed by Pass; a pass's name appears only where data leaves the program
// (stats.json, counters.csv, coefficient files, `accretion passes --json`)
// and is read back by parsePass, which refuses any other name: a pass
// renamed on one side fails a join loudly instead of dropping out of it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace accretion {

enum class Pass : std::uint8_t {
    loadParticles,
    buildLightSampler,
    chooseNearLights,
    buildClusters,
    traceGBuffer,
    estimateLighting,
    presampleLightTiles,
    presampleRegirGrid,
    gatherParticleTexels,
    generateCandidates,
    temporalResampling,
    spatialResampling,
    resampleWorldNeighbours,
    traceShadowRays,
    shadeParticlePixels,
    resampleParticlePixels,
    updateVoxelCache,
    shadeVoxelPixels,
    findNearLights,
    shadeSplitTexels,
    upsampleLighting,
    composeImage,
    writeOutputs,
};
inline constexpr std::size_t kPassCount = static_cast<std::size_t>(Pass::writeOutputs) + 1;

/// How a pass's GPU threads are laid out (what its counters' grid means).
enum class PassGrid : std::uint8_t {
    host,      ///< CPU work of the frame: no GPU dispatch, no counters
    clusters,  ///< one thread per cluster (BLAS), height 1
    pixels,    ///< one thread per pixel (or lighting texel)
    entries,   ///< one thread per presampled entry (tile slot, grid slot)
};

/// How a pass's threads are launched, which decides the warps they form
/// (docs/MODEL.md section 6). tiles: a 2D launch in groups of
/// gpu.group_width x group_height, a warp cut row-major from a group (the
/// image's passes, the particle texel grid's 8x8 blocks). row: a 1D kernel
/// or a one-row launch, a warp of warp_size consecutive threads (a thread
/// per cluster, per entry, per ray of a texel or a cell, in record order).
enum class PassLaunch : std::uint8_t { tiles, row };

/// One row of the pass table.
struct PassInfo {
    Pass pass;
    std::string_view name;   ///< the name in every file the program writes
    Pass parent;             ///< the pass whose timer holds this one's time (itself when top-level)
    PassGrid grid;           ///< what one GPU thread of it is
    PassLaunch launch;       ///< how its threads are cut into warps
    Pass costProxy;          ///< whose per-pass coefficients price it when it has none of its own
    bool readsLights;        ///< its threads read light records at random: its cold_work working set when it traces no rays
    std::string_view reads;  ///< what it reads, in words (`accretion passes`)
};

inline constexpr std::array<PassInfo, kPassCount> kPasses = {{
    {Pass::loadParticles, "loadParticles", Pass::loadParticles, PassGrid::host, PassLaunch::row, Pass::loadParticles, false,
     "the particle file or generator of the frame"},
    {Pass::buildLightSampler, "buildLightSampler", Pass::buildLightSampler, PassGrid::host, PassLaunch::row, Pass::buildLightSampler, false,
     "every particle's emission and position"},
    {Pass::chooseNearLights, "chooseNearLights", Pass::chooseNearLights, PassGrid::host, PassLaunch::row, Pass::chooseNearLights, false,
     "a 64-pixel-wide G-buffer of the view and the light tree (split's pilot)"},
    {Pass::buildClusters, "buildClusters", Pass::buildClusters, PassGrid::clusters, PassLaunch::row, Pass::buildClusters, false,
     "particle positions and radii; the previous frame's BVH when refitting"},
    {Pass::traceGBuffer, "traceGBuffer", Pass::traceGBuffer, PassGrid::pixels, PassLaunch::tiles, Pass::traceGBuffer, false,
     "the camera and the TLAS/BLAS; writes the G-buffer"},
    {Pass::estimateLighting, "estimateLighting", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::estimateLighting, false,
     "the G-buffer, the light sampler and the BVH (shadow rays)"},
    {Pass::presampleLightTiles, "presampleLightTiles", Pass::estimateLighting, PassGrid::entries, PassLaunch::row, Pass::generateCandidates, true,
     "the power alias table and light records"},
    {Pass::presampleRegirGrid, "presampleRegirGrid", Pass::estimateLighting, PassGrid::entries, PassLaunch::row, Pass::generateCandidates, true,
     "the light tiles and light records"},
    {Pass::gatherParticleTexels, "gatherParticleTexels", Pass::estimateLighting, PassGrid::pixels, PassLaunch::row, Pass::gatherParticleTexels, false,
     "the G-buffer (which particles are seen), their positions and billboards; writes the particle texels in Morton order"},
    {Pass::generateCandidates, "generateCandidates", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::generateCandidates, true,
     "the G-buffer, the candidate source and light records; writes reservoirs"},
    {Pass::temporalResampling, "temporalResampling", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::temporalResampling, true,
     "this frame's and the previous frame's reservoirs and G-buffers"},
    {Pass::spatialResampling, "spatialResampling", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::spatialResampling, true,
     "the neighbours' reservoirs and G-buffer texels"},
    {Pass::resampleWorldNeighbours, "resampleWorldNeighbours", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::spatialResampling, true,
     "particle_restir's spatial reuse: the reservoirs and texels of the visible particles either side in world (Morton) order"},
    {Pass::traceShadowRays, "traceShadowRays", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::traceShadowRays, false,
     "the kept reservoir, its light record and the BVH; writes Lr"},
    {Pass::shadeParticlePixels, "shadeParticlePixels", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::shadeParticlePixels, false,
     "the G-buffer and the pixel's particle's texels' Lr (bilinear); writes Lr"},
    {Pass::resampleParticlePixels, "resampleParticlePixels", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::traceShadowRays, true,
     "the G-buffer, the pixel's particle's texels' reservoirs, their light records and the BVH (a shadow ray per pixel); writes Lr"},
    {Pass::updateVoxelCache, "updateVoxelCache", Pass::estimateLighting, PassGrid::entries, PassLaunch::row, Pass::traceShadowRays, true,
     "the particles' boxes (which cells are occupied), render.source's sampler, light records and the BVH; writes the cells"},
    {Pass::shadeVoxelPixels, "shadeVoxelPixels", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::upsampleLighting, false,
     "the G-buffer and the 8 cells around the pixel's point; writes Lr"},
    {Pass::findNearLights, "findNearLights", Pass::estimateLighting, PassGrid::entries, PassLaunch::row, Pass::generateCandidates, true,
     "each visible particle's position and the light tree's nodes (a pruned nearest search, no rays); writes its near lights"},
    {Pass::shadeSplitTexels, "shadeSplitTexels", Pass::estimateLighting, PassGrid::pixels, PassLaunch::row, Pass::traceShadowRays, true,
     "the particle texels, their particle's near lights, the light tree, light records and the BVH (a shadow ray per light); writes the texels' Lr"},
    {Pass::upsampleLighting, "upsampleLighting", Pass::estimateLighting, PassGrid::pixels, PassLaunch::tiles, Pass::upsampleLighting, false,
     "the reduced-resolution lighting grid and the full G-buffer"},
    {Pass::composeImage, "composeImage", Pass::composeImage, PassGrid::pixels, PassLaunch::tiles, Pass::composeImage, false,
     "the G-buffer and Lr; writes Le + Lr"},
    {Pass::writeOutputs, "writeOutputs", Pass::writeOutputs, PassGrid::host, PassLaunch::row, Pass::writeOutputs, false,
     "the frame's layers; writes the EXR, the previews and stats (by the command)"},
}};

namespace detail {
constexpr bool passTableInOrder() {
    for (std::size_t k = 0; k < kPasses.size(); ++k)
        if (static_cast<std::size_t>(kPasses[k].pass) != k) return false;
    return true;
}
constexpr bool passTableNested() {  // one level: a parent is top-level
    for (const PassInfo& p : kPasses)
        if (kPasses[static_cast<std::size_t>(p.parent)].parent != p.parent) return false;
    return true;
}
}  // namespace detail
static_assert(detail::passTableInOrder(), "kPasses row k describes Pass k");
static_assert(detail::passTableNested(), "a pass nests in a top-level pass");

constexpr const PassInfo& passInfo(Pass p) { return kPasses[static_cast<std::size_t>(p)]; }
constexpr std::string_view passName(Pass p) { return passInfo(p).name; }
constexpr bool isNested(Pass p) { return passInfo(p).parent != p; }

/// One run of a pass in a frame: spatialResampling's second iteration is
/// {spatialResampling, 2}, written "spatialResampling[2]".
struct PassRun {
    Pass pass = Pass::loadParticles;
    std::uint32_t run = 1;
    std::string label() const;
    friend bool operator==(const PassRun&, const PassRun&) = default;
    friend auto operator<=>(const PassRun&, const PassRun&) = default;
};

/// The run a label denotes ("traceShadowRays", "spatialResampling[2]");
/// nullopt for any other text.
std::optional<PassRun> parsePassRun(std::string_view label);
/// The pass a name or a run's label denotes; nullopt for any other text.
std::optional<Pass> parsePass(std::string_view name);
/// "a, b, c": every pass name, for errors that name an unknown one.
std::string passNameList();

}  // namespace accretion
