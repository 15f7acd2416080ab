#pragma once
// The voxel radiance cache of seed 004 (docs/MODEL.md section 4b,
// docs/designs.md): its cells, its grid and the bodies of its two passes,
// written once for the CPU (src/render/voxel/) and the GPU twin
// (src/twin/programs.cu, voxel_kernels.cu), over a bridge B:
//
//   const VoxelParams& params()             the frame's grid and settings
//   bool occupied(c)                        some particle's box reaches cell c's stencil
//   CellRay cellRay(c, r)                   ray r of cell c: traceCellRay's (the CPU calls it; the
//                                           twin's rays ran in a launch of their own, one a thread)
//   VoxelCell cell(c)                       the cell as last frame left it
//   void writeCell(c, cell)
//   LightSample sampleLight(sp, rng)        a light from render.source at a cell's point: uniform or
//                                           power (SourcePmf), or the light tree without the cosine
//                                           (LightTreeView, isotropic): the same draws on both
//   bool cellTerm(sp, i, d2, t)             light i's isotropic term at a cell's point (rho = 1), its
//                                           distance clamped at max(dmin_i^2, d2)
//   bool shadows()                          shading.visibility
//   bool visible(sp, i, t)                  a shadow ray (traced and counted by the bridge)
//   GBufferTexel pixel(px); ShadingPoint shadingPoint(g)
//   void writePixelLr(px, Lr)
//
// A cell holds what arrives at its centre x_c from every light, each light
// i a direction w_i and an amount a_i = I_i V(x_c, p_i) / max(d_i^2, dmin_i^2)
// (the light's own clamp: the cell is no particle): its sum A, its first
// moment B = sum a_i w_i (the L1 basis) and its cosine lobe toward the
// camera C = sum a_i max(0, n_c . w_i), n_c the normal a billboard at x_c
// would have. updateVoxelCache estimates them from `rays` lights drawn from
// render.source at x_c (the tree without a cosine), one shadow ray each, and averages them over frames;
// shadeVoxelPixels reads the 8 cells around the pixel's point
// trilinearly, takes out the receiver's own light (i != j, as its
// unshadowed amount at each cell), and shades:
//   isotropic     Lr = rho A / (4 pi)
//   l1            Lr = rho (A + 2 n . B) / (4 pi)  (the clamped cosine's L1 convolution:
//                 exact for light from all around, 3/4 of a light along n)
//   camera        Lr = rho C / pi                   (exact where n = n_c)
// clamped at 0 per channel. Biased: the light at the cells' centres, not at
// the pixel, and blurred over frames.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "accretion/core/math.h"
#include "accretion/core/rng.h"
#include "accretion/geometry/exclusion.h"
#include "accretion/geometry/shading_point.h"
#include "accretion/lighting/light_sample.h"
#include "accretion/lighting/shading.h"
#include "accretion/render/gbuffer_texel.h"
#include "accretion/scene/settings.h"

namespace accretion::voxel {

/// One cell (64 bytes: the GPU reads it in two sectors).
struct VoxelCell {
    Vec3 A{0.0f};               ///< sum of a_i
    Vec3 Bx{0.0f}, By{0.0f}, Bz{0.0f};  ///< sum of a_i w_i, per component of w
    Vec3 C{0.0f};               ///< sum of a_i max(0, n_c . w_i)
    float frames = 0.0f;        ///< frames averaged (0: empty, not occupied last frame)
};
static_assert(sizeof(VoxelCell) == 64, "a cell is 64 bytes");

/// The grid in the frame's coordinates: cubic cells, cell (x, y, z) at
/// index (z ny + y) nx + x, its centre at lower + (x + 1/2, y + 1/2, z + 1/2) h.
struct VoxelGrid {
    Vec3 lower{0.0f};
    float cellSize = 1.0f;
    float invCellSize = 1.0f;
    std::uint32_t nx = 0, ny = 0, nz = 0;
    ACC_HD std::uint32_t count() const { return nx * ny * nz; }
    ACC_HD std::uint32_t index(std::uint32_t x, std::uint32_t y, std::uint32_t z) const { return (z * ny + y) * nx + x; }
    ACC_HD Vec3 centre(std::uint32_t c) const {
        const std::uint32_t x = c % nx, y = (c / nx) % ny, z = c / (nx * ny);
        return lower + cellSize * Vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f);
    }
    /// The trilinear stencil's first cell and weight along one axis: the
    /// cell centre at or below coordinate v (clamped into the grid: outside
    /// it the value is the edge cell's).
    ACC_HD static void stencil(float v, float lower, float inv, std::uint32_t n, std::uint32_t& i0, std::uint32_t& i1, float& f) {
        const float u = (v - lower) * inv - 0.5f;
        const float fl = floorf(u);
        f = u - fl;
        const int i = int(fl);
        i0 = i < 0 ? 0u : (i >= int(n) ? n - 1u : std::uint32_t(i));
        i1 = i + 1 < 0 ? 0u : (i + 1 >= int(n) ? n - 1u : std::uint32_t(i + 1));
    }
    /// The cells whose stencils a point within `reach` of p may read, per
    /// axis [lo, hi] (the cells that must be up to date for it).
    ACC_HD void reach(const Vec3& p, float reach, std::uint32_t lo[3], std::uint32_t hi[3]) const {
        const std::uint32_t n[3] = {nx, ny, nz};
        for (int k = 0; k < 3; ++k) {
            std::uint32_t a0, a1, b0, b1;
            float f;
            stencil(p[k] - reach, lower[k], invCellSize, n[k], a0, a1, f);
            stencil(p[k] + reach, lower[k], invCellSize, n[k], b0, b1, f);
            lo[k] = a0;
            hi[k] = b1;
        }
    }
};

/// A particle's reach from its centre: its billboard's corners (r sqrt 2),
/// with a margin.
ACC_HD inline float particleReach(float r) { return 1.5f * r; }

/// What both passes read of the frame.
struct VoxelParams {
    VoxelGrid grid;
    std::uint32_t rays = 8;       ///< voxel.rays
    float history = 16.0f;        ///< voxel.history
    float nearClamp2 = 0.0f;      ///< (voxel.near_clamp x the cell size)^2: a light nearer a cell's centre counts as that far
    VoxelBasis basis = VoxelBasis::l1;
    std::uint32_t frame = 0;
    std::uint64_t seed = 0;
    Vec3 camera{0.0f};            ///< the camera's position (frame coordinates)
    /// geometry.orientation view_plane: every billboard faces `planeNormal`
    /// (towards the camera); else a billboard at p faces the camera's position.
    bool facesPlane = false;
    Vec3 planeNormal{0.0f, 0.0f, 1.0f};
    ACC_HD Vec3 cameraNormal(const Vec3& x) const {
        if (facesPlane) return planeNormal;
        const Vec3 d = camera - x;
        const float len = sqrtf(d.x * d.x + d.y * d.y + d.z * d.z);
        return len > 0.0f ? d / len : planeNormal;
    }
};

/// The shading point of a cell's centre: no particle of its own.
ACC_HD inline ShadingPoint cellPoint(const Vec3& x) {
    ShadingPoint sp;
    sp.x = x;
    sp.n = sp.ng = Vec3(0.0f, 0.0f, 1.0f);
    sp.rho = Vec3(1.0f);
    sp.self = kNotExcluded;
    sp.centre = x;
    sp.local = Vec3(0.0f);
    return sp;
}

/// A cell's value scaled by s.
ACC_HD inline void addScaled(VoxelCell& out, const VoxelCell& c, float s) {
    out.A += s * c.A;
    out.Bx += s * c.Bx;
    out.By += s * c.By;
    out.Bz += s * c.Bz;
    out.C += s * c.C;
}

/// One light's amount a (RGB) arriving from direction w, added to a cell's sums.
ACC_HD inline void addLight(VoxelCell& c, const Vec3& a, const Vec3& w, const Vec3& nc) {
    c.A += a;
    c.Bx += a * w.x;
    c.By += a * w.y;
    c.Bz += a * w.z;
    const float cosC = nc.x * w.x + nc.y * w.y + nc.z * w.z;
    if (cosC > 0.0f) c.C += a * cosC;
}

/// What one ray of a cell brings: the amount a (0 when the light was not
/// seen) and its direction.
struct CellRay {
    Vec3 a{0.0f};
    Vec3 w{0.0f, 0.0f, 1.0f};
};

/// Ray r of cell c: a light from render.source at the cell's centre, from
/// the ray's own stream (so that the rays of a cell can run apart), and
/// a = 4 pi x its isotropic term / (pdf rays) when seen.
template <class B>
ACC_HD_BODY CellRay traceCellRay(B& b, std::uint32_t c, std::uint32_t r) {
    const VoxelParams& p = b.params();
    const ShadingPoint sp = cellPoint(p.grid.centre(c));
    PortableRng rng(c, p.frame, RngPass::voxelCache, p.seed, r + 1);
    const LightSample s = b.sampleLight(sp, rng);
    CellRay out;
    if (!(s.pdf > 0.0f)) return out;
    LightTerm t;
    if (!b.cellTerm(sp, s.i, p.nearClamp2, t)) return out;
    if (b.shadows() && !b.visible(sp, s.i, t)) return out;
    out.a = t.value * (4.0f * kPi / (float(p.rays) * s.pdf));
    out.w = t.w;
    return out;
}

/// updateVoxelCache at cell c: an empty cell unless occupied; else its
/// `rays` rays (traceCellRay) summed in order, this frame's estimate
/// averaged with the cell's last value over min(frames + 1, history) frames.
template <class B>
ACC_HD_BODY void updateVoxelCell(B& b, std::uint32_t c) {
    const VoxelParams& p = b.params();
    if (!b.occupied(c)) {
        b.writeCell(c, VoxelCell{});
        return;
    }
    const Vec3 nc = p.cameraNormal(p.grid.centre(c));
    VoxelCell est;
    for (std::uint32_t r = 0; r < p.rays; ++r) {
        const CellRay ray = b.cellRay(c, r);
        addLight(est, ray.a, ray.w, nc);
    }
    VoxelCell cell = b.cell(c);
    const float n = cell.frames + 1.0f < p.history ? cell.frames + 1.0f : p.history;
    const float keep = 1.0f - 1.0f / n;
    VoxelCell out;
    addScaled(out, cell, keep);
    addScaled(out, est, 1.0f / n);
    out.frames = n;
    b.writeCell(c, out);
}

/// shadeVoxelPixels at image pixel px: the cells' trilinear value at the
/// pixel's point, less its own particle's unshadowed amount at each of
/// them, shaded in voxel.basis (see the top of this file).
template <ShadingModel SM, class B>
ACC_HD_BODY void shadeVoxelPixel(B& b, std::size_t px) {
    const GBufferTexel g = b.pixel(px);
    if (!g.hit()) {
        b.writePixelLr(px, Vec3(0.0f));
        return;
    }
    const VoxelParams& p = b.params();
    const VoxelGrid& grid = p.grid;
    const ShadingPoint sp = b.shadingPoint(g);
    std::uint32_t i[3][2];
    float f[3];
    const std::uint32_t n[3] = {grid.nx, grid.ny, grid.nz};
    for (int k = 0; k < 3; ++k) VoxelGrid::stencil(sp.x[k], grid.lower[k], grid.invCellSize, n[k], i[k][0], i[k][1], f[k]);
    VoxelCell sum;
    for (std::uint32_t corner = 0; corner < 8; ++corner) {
        const std::uint32_t cx = corner & 1u, cy = (corner >> 1) & 1u, cz = corner >> 2;
        const float w = (cx ? f[0] : 1.0f - f[0]) * (cy ? f[1] : 1.0f - f[1]) * (cz ? f[2] : 1.0f - f[2]);
        if (!(w > 0.0f)) continue;
        const std::uint32_t c = grid.index(i[0][cx], i[1][cy], i[2][cz]);
        const VoxelCell cell = b.cell(c);
        addScaled(sum, cell, w);
        if (cell.frames > 0.0f) {  // the receiver's own light, as the cell saw it unshadowed
            const Vec3 x = grid.centre(c);
            LightTerm t;
            if (b.cellTerm(cellPoint(x), g.particle, p.nearClamp2, t)) {
                VoxelCell own;
                addLight(own, t.value * (4.0f * kPi), t.w, p.cameraNormal(x));
                addScaled(sum, own, -w);
            }
        }
    }
    Vec3 Lr;
    if constexpr (SM == ShadingModel::isotropic) {
        Lr = sp.rho * sum.A * kInv4Pi;
    } else {
        if (p.basis == VoxelBasis::camera) {
            Lr = sp.rho * sum.C * kInvPi;
        } else {
            const Vec3 Bn = sp.n.x * sum.Bx + sp.n.y * sum.By + sp.n.z * sum.Bz;
            Lr = sp.rho * (sum.A + 2.0f * Bn) * kInv4Pi;
        }
    }
    Lr = Vec3(Lr.x > 0.0f ? Lr.x : 0.0f, Lr.y > 0.0f ? Lr.y : 0.0f, Lr.z > 0.0f ? Lr.z : 0.0f);
    b.writePixelLr(px, Lr);
}

}  // namespace accretion::voxel
