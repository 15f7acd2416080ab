#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

enum class OmmState : std::uint8_t { transparent = 0, opaque = 1, unknown = 2 };

/// Opacity micromap of the billboard's disc alpha (docs/MODEL.md section 6): each
/// of the quad's two uv triangles, (0,0),(1,0),(1,1) and (0,0),(1,1),(0,1),
/// is split into 4^L micro-triangles on its barycentric grid, each classified
/// exactly against the inscribed disc as opaque (inside), transparent
/// (outside) or unknown (crossed by the circle). 4-state keeps unknown (only
/// those invoke any-hit, so the image is that of alpha testing); 2-state
/// turns unknown into opaque when at least half of it is covered (no any-hit,
/// a different image). Every billboard shares the same two arrays.
class OpacityMicromap {
public:
    OpacityMicromap(std::uint32_t level, bool fourState);

    std::uint32_t level() const { return level_; }
    bool fourState() const { return fourState_; }
    std::uint32_t microTriangles() const { return 1u << (2 * level_); }  ///< per triangle

    /// State of micro-triangle `index` of triangle `tri` (0 or 1).
    OmmState state(std::uint32_t tri, std::uint32_t index) const { return states_[tri][index]; }
    /// State at the barycentrics (u, v) of triangle `tri` (Embree's hit u, v).
    OmmState lookup(std::uint32_t tri, float u, float v) const { return states_[tri][microIndex(level_, u, v)]; }

    /// Micro-triangle of barycentrics (u, v) at level L: row j = floor(v n),
    /// column i = floor(u n), the upper triangle of a cell when the in-cell
    /// fractions sum past 1; rows are stored one after the other.
    static std::uint32_t microIndex(std::uint32_t level, float u, float v);
    /// The barycentric (u, v) corners of micro-triangle `index` at level L.
    static std::array<Vec2, 3> microCorners(std::uint32_t level, std::uint32_t index);
    /// The quad uv of barycentrics (u, v) on triangle `tri`.
    static Vec2 quadUvOf(std::uint32_t tri, Vec2 bary) {
        return tri ? Vec2(bary.x, bary.x + bary.y) : Vec2(bary.x + bary.y, bary.y);
    }
    /// Exact classification of a uv triangle against the disc (margin 1e-6 on
    /// both sides: borderline micro-triangles are unknown).
    static OmmState classify(const std::array<Vec2, 3>& uv);

    std::uint64_t count(OmmState s) const;  ///< over both triangles
    /// Bytes of one triangle's array (2 bits per micro-triangle for 4-state, 1 for 2-state).
    std::uint64_t arrayBytes() const;

private:
    std::uint32_t level_;
    bool fourState_;
    std::array<std::vector<OmmState>, 2> states_;
};

/// OMM memory for n billboards: shared arrays (one per uv triangle, plus a
/// 16-bit index per triangle) against one array per triangle.
struct OmmMemory {
    std::uint64_t sharedBytes = 0;
    std::uint64_t perTriangleBytes = 0;
};
OmmMemory ommMemory(const OpacityMicromap& omm, std::uint64_t billboards);

}  // namespace accretion
