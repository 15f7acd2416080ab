#pragma once
// particle_restir's lighting grid on the CPU: the slots and texels of a
// frame (particle_texels.h has the rules the CPU and the twin share).
#include <cstdint>
#include <vector>

#include "accretion/counters/thread_counters.h"
#include "accretion/render/gbuffer.h"
#include "accretion/render/particle_texels.h"

namespace accretion {

/// A frame's particle texels (gatherParticleTexels): the slots, and the
/// texels as a G-buffer kTexelRowWidth wide (the last row's tail misses).
struct ParticleTexels {
    std::uint32_t side = 1, layers = 1;
    std::vector<std::uint32_t> particleOf;  ///< slot -> particle
    std::vector<std::uint32_t> slotOf;      ///< particle -> slot, kNoSlot when not visible
    GBuffer grid;
    std::uint32_t perParticle() const { return side * side * layers; }
    std::uint32_t visible() const { return static_cast<std::uint32_t>(particleOf.size()); }
    std::size_t texels() const { return std::size_t(visible()) * perParticle(); }
};

/// gatherParticleTexels: the particles some pixel of `gbuffer` sees, in
/// Morton order of their positions over the particles' bounding cube (ties
/// by id), and their side x side x layers texels on the billboards `bvh`
/// holds for the camera (particle_restir's restir.texels and texel_rays,
/// at their centres; particle_split's particle_split.texels and one layer,
/// where `points` puts them: particle_split.texel_point).
ParticleTexels gatherParticleTexels(const GBuffer& gbuffer, const Particles& particles, const ParticleBvh& bvh,
                                    const Camera& camera, ShadingModel model, std::uint32_t side, std::uint32_t layers,
                                    const TexelPointRule& points);

/// The steps of gatherParticleTexels' kernels beside its grid of pixels
/// (PassCounters::itemSteps), as the twin launches them, an item a step
/// (CUB's select and sort: the items each of their kernels passes over): a
/// thread per particle to list the ids and one to select the visible ones;
/// per visible particle its Morton key, the sort's histogram and its
/// kSortDigitPasses passes (8-bit digits of a 63-bit key), and its slot; a
/// thread per texel of the grid written. Its dispatches: two memsets, the
/// visible flags, the ids, the select, the keys, the sort's histogram, scan
/// and digit passes, the slots and the texels (kGatherDispatches). On the
/// H200 (no RT cores; bench/gpu/run.sh gather_ncu) the digit passes take
/// 13 us each whatever the keys, the texels 0.10-0.12 ns each, the rest less.
inline constexpr std::uint64_t kSortDigitPasses = 8;
inline constexpr std::uint64_t kGatherDispatches = 10 + kSortDigitPasses;
std::uint64_t gatherItemSteps(std::size_t particles, const ParticleTexels& texels);

/// Counting mode: gatherParticleTexels's per-pixel work (the G-buffer
/// texel read, the particle's visible flag written) and its other kernels'
/// steps (gatherItemSteps).
void recordGatherParticleTexels(const GBuffer& gbuffer, const Particles& particles, const ParticleBvh& bvh, const ParticleTexels& texels,
                                PassCounters& pc);

}  // namespace accretion
