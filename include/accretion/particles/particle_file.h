#pragma once
#include <filesystem>
#include <string_view>

#include "accretion/particles/particles.h"

namespace accretion {

/// The GPU's ParticleData record: {float3 position; float radius; float3 emission; float opacity;}.
inline constexpr std::size_t kParticleRecordBytes = 32;

enum class ParticleFormat { raw, ply };

/// Read a particle file. The format is found by its magic: a file that
/// starts with the line `ply` (LF or CRLF) is binary little-endian PLY, one
/// named `.ply` (any case) without it is refused, anything else is raw
/// records. PLY: the header is read line by line; the vertex properties
/// x y z radius emission_r emission_g emission_b (float, float32, double,
/// float64) are required, opacity is optional (those types or uchar/uint8,
/// 0..255 = 0..1, default 1); other scalar properties and elements are
/// skipped, list properties refused; unnamed or duplicate properties are
/// refused naming the header line; the body must hold exactly what the
/// header declares. Fills position, radius, emission, opacity; other fields
/// get defaults. Throws InputError naming the file and the header line or
/// the record index of the first bad record.
Particles readParticles(const std::filesystem::path& file);

/// The same from bytes in memory (`file` names them in messages).
Particles parseParticles(const std::filesystem::path& file, std::string_view bytes);

/// What a particle file holds, from its header and size alone (the checks
/// of readParticles short of the records' values): its format and count.
struct ParticleFileInfo {
    ParticleFormat format;
    std::size_t count;
};
ParticleFileInfo inspectParticleFile(const std::filesystem::path& file);

/// Write position, radius, emission, opacity atomically (temp file + rename).
void writeParticles(const std::filesystem::path& file, const Particles& particles, ParticleFormat format);

}  // namespace accretion
