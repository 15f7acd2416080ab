#pragma once
// A render run as a library object: its checkpoint loaded and checked, the
// frame loop, checkpoints every few seconds, and one signal path (SIGINT and
// SIGTERM stop it at the next safe point, the frames written so far whole).
// `accretion render` and batch's jobs run through it (docs/batches.md).
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "accretion/io/accumulation_file.h"
#include "accretion/io/checkpoint.h"
#include "accretion/render/frame_renderer.h"
#include "accretion/render/shard.h"

namespace accretion {

/// The frames [first, end) a run renders, and how it is cut (render --shard).
struct Sharding {
    Shard shard;                  ///< this run's shard (whole: the run)
    bool accumulating = true;     ///< its lighting is sums of chunks (every estimator without reuse): checkpointed
    bool bySamples = false;       ///< shards split every frame's samples (else the frames)
    std::uint32_t first = 0, end = 0;
    Shard samples() const { return bySamples ? shard : Shard{}; }
};

/// What a run takes from its command line.
struct SessionOptions {
    bool resume = false;             ///< continue from the checkpoint (without it, an existing checkpoint is an error)
    double checkpointEvery = 300.0;  ///< seconds between checkpoints (0: only when stopped)
    bool quiet = false;              ///< no progress on stderr
};

class RenderSession {
public:
    /// Writes a frame's outputs as it ends (timing writeOutputs in its stats) and returns its stats entry.
    using FrameWriter = std::function<nlohmann::json(std::uint32_t frame, const FrameImage& image, FrameStats& stats,
                                                     const Accumulation& sums)>;
    struct Totals {
        double seconds = 0.0;
        std::uint64_t shadowRays = 0;
        double lightingSeconds = 0.0;  ///< estimateLighting's, summed over the frames
    };

    /// A run of `settings` (its TOML `settingsToml`) over `sharding`, whose
    /// outputs are guarded and locked by the caller; `stats` is its
    /// stats.json so far (the header), to which the frames are added. Loads
    /// the checkpoint to resume (Checkpoint::load; one of other pixels is
    /// the user's error, naming the file).
    RenderSession(const Settings& settings, const std::string& checkpointFile, const std::string& settingsToml,
                  const Sharding& sharding, SessionOptions options, nlohmann::json& stats);

    /// Renders the remaining frames, each written by `write`; throws
    /// Interrupted after saving a checkpoint when a signal stops it.
    Totals run(const FrameWriter& write);
    /// The run is complete: its checkpoint goes.
    void finish() const { checkpoint_.remove(); }

private:
    void saveCheckpoint(std::uint32_t frame, const Accumulation& acc);
    [[noreturn]] void interrupt(int signal, std::uint32_t frame, const Accumulation& acc) const;
    [[noreturn]] void stopBetweenFrames(int signal, std::uint32_t next) const;

    const Settings& settings_;
    const Sharding& sharding_;
    SessionOptions options_;
    nlohmann::json& stats_;
    Checkpoint checkpoint_;
    std::uint32_t firstFrame_;
    std::optional<AccumulationFile> resumed_;
    std::chrono::steady_clock::time_point lastCheckpoint_;
};

}  // namespace accretion
