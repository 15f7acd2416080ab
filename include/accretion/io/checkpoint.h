#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "accretion/io/accumulation_file.h"

namespace accretion {

/// The header every accumulation file of a run carries: its kind
/// ("checkpoint" or "shard"), the version, the effective settings and
/// their hash, the shard ("i/n") and the frame.
nlohmann::json accumulationHeader(const char* kind, const std::string& settingsToml, const std::string& shard,
                                  std::uint32_t frame);

/// The checkpoint of one render run (NAME.checkpoint): the sums of the frame
/// in progress and the stats of the finished frames.
class Checkpoint {
public:
    Checkpoint(std::filesystem::path file, std::string settingsToml, std::string shard)
        : file_(std::move(file)), settings_(std::move(settingsToml)), shard_(std::move(shard)) {}

    const std::filesystem::path& file() const { return file_; }

    /// The checkpoint to continue, if any. Without `resume` an existing
    /// checkpoint is an error (it is not overwritten); with it, one of
    /// another version, settings or shard, of a frame outside
    /// [firstFrame, endFrame), or corrupted, is refused (InputError).
    std::optional<AccumulationFile> load(bool resume, std::uint32_t firstFrame, std::uint32_t endFrame) const;

    /// Write atomically: `frame` in progress with `acc`, after `finishedFrames` (their stats).
    void save(std::uint32_t frame, const Accumulation& acc, const nlohmann::json& finishedFrames) const;

    /// The run is complete: nothing left to resume.
    void remove() const;

private:
    std::filesystem::path file_;
    std::string settings_;
    std::string shard_;
};

}  // namespace accretion
