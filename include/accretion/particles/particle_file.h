#pragma once
#include <filesystem>

#include "accretion/particles/particles.h"

namespace accretion {

/// The GPU's ParticleData record: {float3 position; float radius; float3 emission; float opacity;}.
inline constexpr std::size_t kParticleRecordBytes = 32;

enum class ParticleFormat { raw, ply };

/// Format from the extension: .ply is PLY, anything else the raw GPU buffer.
ParticleFormat particleFormatOf(const std::filesystem::path& file);

/// Read a particle file (raw little-endian records or binary PLY). Fills
/// position, radius, emission, opacity; other fields get defaults. Throws
/// InputError naming the file and the record index of the first bad record.
Particles readParticles(const std::filesystem::path& file);

/// Write position, radius, emission, opacity atomically (temp file + rename).
void writeParticles(const std::filesystem::path& file, const Particles& particles, ParticleFormat format);

}  // namespace accretion
