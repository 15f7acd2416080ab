#pragma once
#include <cstdint>

#include "accretion/core/gbuffer_texel_layout.h"

namespace accretion::gpu_layout {

/// Bytes of the GPU's buffers as the counters charge them (docs/MODEL.md section 6).
/// G-buffer texel: the one the lighting passes stream, on the CPU and in the
/// twin whose timings calibrate the model (particle id, local point, shading
/// and geometric normals, depth: 44 B). A compact texel (octahedral normals,
/// no geometric normal: 24 B) would read less; it is not what is timed.
inline constexpr std::uint32_t kGBufferTexel = sizeof(GBufferTexel);
/// Particle record: the raw 32-byte GPU record (position, radius, emission, opacity, type).
inline constexpr std::uint32_t kParticleRecord = 32;
/// Radiance written per pixel: RGBA16F.
inline constexpr std::uint32_t kRadiance = 8;
/// Alias-table entry (probability + alias) read per power-sampled candidate.
inline constexpr std::uint32_t kAliasEntry = 8;
/// A light-tree node (centre, radius, power, clamp, child, count, box): read twice per level of a tree traversal.
inline constexpr std::uint32_t kLightTreeNode = 56;
/// A presampled light (RTXDI's RIS buffer entry: light index, pdf or W):
/// a light tile's entry, a ReGIR slot.
inline constexpr std::uint32_t kRisEntry = 8;
/// Ray payloads of the pipeline (TraceRay) form: primary hit (t, instance,
/// primitive, barycentrics) and shadow visibility.
inline constexpr std::uint32_t kPrimaryPayload = 16;
inline constexpr std::uint32_t kShadowPayload = 4;
/// A TLAS's bytes per instance as OptiX 9.0 builds it (the H100 twin's
/// tlas_bytes: 208,001,152 for 1M instances, 254,208 for 1240), a traced
/// pass's working set beside its BLAS.
inline constexpr std::uint32_t kTlasInstanceBytes = 208;

}  // namespace accretion::gpu_layout
