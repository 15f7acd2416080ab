#include "accretion/io/provenance.h"

#include <fmt/format.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/version.h"

namespace accretion {

OutputMetadata frameMetadata(const Settings& settings, const std::string& settingsToml, std::uint32_t frame,
                             std::uint64_t seed, std::string_view shard, double seconds) {
    return {
        {"version", std::string(version())},
        {"scene", settings.scenePath},
        {"frame", std::to_string(frame)},
        {"estimator", std::string(enumName(settings.render.estimator))},
        {"samples", std::to_string(settings.render.samples)},
        {"seed", std::to_string(seed)},
        {"shard", std::string(shard)},
        {"render_time_s", fmt::format("{:.6f}", seconds)},
        {"settings", settingsToml},
    };
}

nlohmann::json statsHeader(const Settings& settings, const std::string& settingsToml) {
    return {
        {"version", std::string(version())},
        {"scene", settings.scenePath},
        {"estimator", std::string(enumName(settings.render.estimator))},
        {"seed", settings.render.seed},
        {"samples", settings.render.samples},
        {"settings", settingsToml},
        {"frames", nlohmann::json::array()},
    };
}

void writeJson(const std::filesystem::path& file, const nlohmann::json& doc) {
    writeFileAtomic(file, doc.dump(2) + "\n");
}

}  // namespace accretion
