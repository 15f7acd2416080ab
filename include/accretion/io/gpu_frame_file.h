#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "accretion/core/math.h"
#include "accretion/geometry/camera.h"

namespace accretion {

/// A frame made by accretion-optix (the OptiX twin of the GPU pipeline, src/twin)
/// as it leaves the GPU machine: the layers `render` writes to its EXR, raw,
/// with what made them. `accretion import-gpu` turns it into render's EXR.
///
/// File: "ACCGPUF1", a little-endian uint64 header length, the header (JSON:
/// width, height, frame, camera, metadata, planes), then the planes the
/// header lists, in this order, each width x height, row-major,
/// little-endian: L, Le, Lr, normal (float3), depth (float), particle
/// (uint32), and for the Monte Carlo estimators Lr_stderr (float3), spp
/// (float) and rejected (float). Lr is always there; a frame written for
/// `bias` (accretion-optix --lr-only) holds Lr alone. A header without
/// "planes" holds the first six.
struct GpuFrame {
    std::uint32_t width = 0, height = 0, frame = 0;
    CameraPose camera;                           ///< world space, jitter included
    std::map<std::string, std::string> metadata; ///< the EXR's accretion:* attributes (settings, seed, version, device ...)
    std::vector<Vec3> L, Le, Lr, normal;
    std::vector<float> depth;
    std::vector<std::uint32_t> particle;         ///< kNoParticle (0xffffffff) on a miss
    std::vector<Vec3> Lr_stderr;                 ///< uniform / power: the standard error of Lr (else empty)
    std::vector<float> spp, rejected;            ///< uniform / power: samples taken, non-finite samples rejected

    /// Every plane present (what import-gpu needs).
    bool complete() const { return !L.empty() && !Le.empty() && !normal.empty() && !depth.empty() && !particle.empty(); }
};

/// Write atomically (no half-written file is ever left at `file`); empty
/// planes (except Lr) are left out.
void writeGpuFrame(const std::filesystem::path& file, const GpuFrame& frame);
/// Read; a truncated, foreign or inconsistent file is an InputError naming it.
GpuFrame readGpuFrame(const std::filesystem::path& file);

}  // namespace accretion
