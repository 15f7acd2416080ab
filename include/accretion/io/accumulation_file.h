#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "accretion/render/accumulation.h"

namespace accretion {

/// An accumulation on disk: a checkpoint of a running render, or the part
/// a shard contributes to a merge. Binary, little-endian:
///   "ACCRACC1", u64 header length, header (JSON), the per-pixel arrays
///   (sum, sumSq as f64 x3; n u32; done u8; rejected u32), FNV-1a 64 of all
///   preceding bytes.
/// The header carries the version, the settings (TOML) and their hash, the
/// frame, shard, chunk range and whatever the writer adds (finished frames).
struct AccumulationFile {
    nlohmann::json header;
    Accumulation acc;
};

/// FNV-1a 64 of `bytes` (settings hashes, file checksums).
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t h = 0xcbf29ce484222325ull);

/// Atomic (temp + rename).
void writeAccumulationFile(const std::filesystem::path& file, const AccumulationFile& content);

/// Throws InputError naming the file and what is wrong (not an accumulation
/// file, truncated, checksum mismatch, array sizes).
AccumulationFile readAccumulationFile(const std::filesystem::path& file);
/// The same from a file's bytes in memory (`file` names them in messages).
AccumulationFile parseAccumulationFile(const std::string& bytes, const std::filesystem::path& file);

/// If `settings` (TOML) differ from those stored in `header`, a message
/// naming the first differing line; empty when they match.
std::string settingsDifference(const nlohmann::json& header, const std::string& settings);

}  // namespace accretion
