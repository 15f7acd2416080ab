#pragma once
// A brute-force, double-precision reference of docs/MODEL.md section 3 that
// shares no code with the renderer: its own camera rays, billboard frames,
// ray-quad / ray-disc / ray-sphere tests and shading sum; no Embree, no
// render/ headers. It reads only the inputs (settings and particle arrays).
// Every primary ray tests every particle and every shadow segment tests
// every particle: O(pixels x N^2), for scenes of a few hundred particles.
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "accretion/particles/particles.h"
#include "accretion/scene/settings.h"

namespace accretion::test {

inline constexpr std::uint32_t kOracleMiss = 0xffffffffu;

struct OracleImage {
    std::uint32_t width = 0, height = 0;
    std::vector<std::uint32_t> particle;  ///< hit particle, kOracleMiss on a miss
    std::vector<glm::dvec3> Lr;           ///< reflected light (0 on a miss)
    /// Pixels whose answer hangs on a decision closer than `margin` (relative)
    /// to a silhouette: the primary ray grazes an edge, or a shadow segment
    /// that carries more than 1e-6 of the pixel's unshadowed light grazes an
    /// occluder's edge or ends within the margin of a crossing. Float
    /// renderers may legitimately decide those either way.
    std::vector<std::uint8_t> grazing;
    std::size_t hits() const;
};

/// Render frame 0 of a static camera (`settings.camera`, its path ignored)
/// with `settings.geometry` (primitive, orientation, alpha) and
/// `settings.shading` (model, dmin, visibility); particles as given
/// (positions, radius, emission, albedo, velocity for `velocity` billboards).
OracleImage oracleRender(const Settings& settings, const Particles& particles, double margin = 1e-5);

}  // namespace accretion::test
