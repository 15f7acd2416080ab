#pragma once
// The jobs file of `accretion batch`: [batch] output_dir, parallel and
// [[job]] tables.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace accretion::cmd {

/// One render of the batch: a scene, frames, seed and render options.
struct Job {
    std::string name;
    std::string scene;
    std::string frames;               ///< "A:B" or "A"; empty: the scene's
    std::optional<std::uint64_t> seed;
    std::string estimator;
    std::optional<std::uint32_t> spp;
    std::string output;               ///< EXR pattern; default <output_dir>/<name>/{scene}.{frame}.exr
    std::string shard;
    std::vector<std::string> defines;
};

/// What a jobs file says. Paths (scenes, outputs, output_dir) are relative
/// to the file; the command line overrides output_dir and parallel.
struct JobsFile {
    std::vector<Job> jobs;
    std::optional<std::string> outputDir;
    std::optional<int> parallel;
};

/// Parse a jobs file's text (`file` names it in messages and anchors its
/// relative paths). Every key is checked: an unknown or mistyped one, or a
/// job name that is not a name, is refused naming its line (InputError).
JobsFile parseJobsFile(std::string_view text, const std::filesystem::path& file);
JobsFile readJobsFile(const std::filesystem::path& file);

/// Why `name` cannot name a job (its outputs are <output_dir>/<name>/...),
/// or empty: a name, not a path.
std::string badJobName(const std::string& name);

/// A generated job name (from a scene's stem): the characters a name allows.
std::string sanitizeJobName(std::string name);

}  // namespace accretion::cmd
