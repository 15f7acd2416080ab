#include "accretion/io/checkpoint.h"

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/version.h"

namespace accretion {

nlohmann::json accumulationHeader(const char* kind, const std::string& settingsToml, const std::string& shard,
                                  std::uint32_t frame) {
    return {{"kind", kind},
            {"version", std::string(version())},
            {"settings", settingsToml},
            {"settings_hash", fmt::format("{:016x}", fnv1a64(settingsToml))},
            {"shard", shard},
            {"frame", frame}};
}

std::optional<AccumulationFile> Checkpoint::load(bool resume, std::uint32_t firstFrame, std::uint32_t endFrame) const {
    const std::string name = file_.string();
    if (!std::filesystem::exists(file_)) return std::nullopt;
    if (!resume)
        throw InputError(fmt::format("{}: a checkpoint of an interrupted run is here; continue it with --resume "
                                     "or delete it to start over", name));
    AccumulationFile f = readAccumulationFile(file_);
    const nlohmann::json& h = f.header;
    if (h.value("kind", "") != "checkpoint")
        throw InputError(fmt::format("{}: a {} file, not a checkpoint", name, h.value("kind", "?")));
    if (h.value("version", "") != version())
        throw InputError(fmt::format("{}: checkpoint written by accretion {}, this is {}: its samples would not "
                                     "continue the same streams", name, h.value("version", "?"), version()));
    if (const std::string diff = settingsDifference(h, settings_); !diff.empty())
        throw InputError(fmt::format("{}: checkpoint of other settings: {}", name, diff));
    if (h.value("shard", "") != shard_)
        throw InputError(fmt::format("{}: checkpoint of shard {}, this run is shard {}", name, h.value("shard", "?"), shard_));
    const std::uint32_t frame = h.value("frame", ~0u);
    if (frame < firstFrame || frame >= endFrame || !h.contains("finished_frames"))
        throw InputError(fmt::format("{}: checkpoint of frame {}, outside this run's frames", name, frame));
    return f;
}

void Checkpoint::save(std::uint32_t frame, const Accumulation& acc, const nlohmann::json& finishedFrames) const {
    AccumulationFile f{accumulationHeader("checkpoint", settings_, shard_, frame), acc};
    f.header["finished_frames"] = finishedFrames;
    writeAccumulationFile(file_, f);
}

void Checkpoint::remove() const {
    std::error_code ignored;
    std::filesystem::remove(file_, ignored);
}

}  // namespace accretion
