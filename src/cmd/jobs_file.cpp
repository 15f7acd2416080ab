#include "jobs_file.h"

#include <cctype>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "accretion/core/error.h"
#include "accretion/core/read_file.h"
#include "accretion/scene/toml_limits.h"

namespace accretion::cmd {
namespace {

std::string where(const toml::node& n) {
    const auto& src = n.source();
    return fmt::format("{}:{}", src.path ? *src.path : std::string("<jobs>"), src.begin.line);
}

}  // namespace

std::string badJobName(const std::string& name) {
    if (name.empty()) return "empty";
    if (name.size() > 128) return fmt::format("{} characters (at most 128)", name.size());
    if (name.front() == '.') return "starts with '.'";
    for (char c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '+'))
            return c == '/' || c == '\\' ? "is a path" : fmt::format("holds '{}'", c < 0x20 ? '?' : c);
    return {};
}

std::string sanitizeJobName(std::string name) {
    for (char& c : name)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '+')) c = '_';
    if (name.empty() || name.front() == '.') name = "job" + name;
    return name.substr(0, 128);
}

JobsFile parseJobsFile(std::string_view text, const std::filesystem::path& file) {
    JobsFile result;
    checkTomlNesting(text, file.string());
    toml::table root;
    try {
        root = toml::parse(text, file.string());
    } catch (const toml::parse_error& e) {
        const auto& src = e.source();
        throw InputError(fmt::format("{}:{}: {}", file.string(), src.begin.line, e.description()));
    }
    const std::filesystem::path dir = file.parent_path();
    auto path = [&](const std::string& p) { return std::filesystem::path(p).is_relative() && !dir.empty() ? (dir / p).string() : p; };
    auto str = [&](const toml::node& n, const std::string& key) {
        if (!n.is_string()) throw InputError(fmt::format("{}: {}: expected a string", where(n), key));
        return n.as_string()->get();
    };
    auto integer = [&](const toml::node& n, const std::string& key, std::int64_t lo, std::int64_t hi) {
        if (!n.is_integer() || n.as_integer()->get() < lo || n.as_integer()->get() > hi)
            throw InputError(fmt::format("{}: {}: expected an integer in [{}, {}]", where(n), key, lo, hi));
        return n.as_integer()->get();
    };
    for (const auto& [key, node] : root) {
        if (key.str() == "batch") {
            const toml::table* t = node.as_table();
            if (!t) throw InputError(fmt::format("{}: [batch] must be a table", where(node)));
            for (const auto& [k, v] : *t) {
                if (k.str() == "output_dir") result.outputDir = path(str(v, "batch.output_dir"));
                else if (k.str() == "parallel") result.parallel = int(integer(v, "batch.parallel", 1, 256));
                else throw InputError(fmt::format("{}: batch.{}: unknown key (output_dir, parallel)", where(v), k.str()));
            }
        } else if (key.str() != "job") {
            throw InputError(fmt::format("{}: {}: unknown table (expected [batch] and [[job]])", where(node), key.str()));
        }
    }
    const toml::array* jobs = root["job"].as_array();
    if (!jobs || jobs->empty())
        throw InputError(fmt::format("{}: no [[job]] tables: nothing to run", file.string()));
    std::vector<Job>& out = result.jobs;
    for (const toml::node& n : *jobs) {
        const toml::table* t = n.as_table();
        if (!t) throw InputError(fmt::format("{}: job must be a table ([[job]])", where(n)));
        Job j;
        for (const auto& [k, v] : *t) {
            const std::string key = "job." + std::string(k.str());
            if (k.str() == "name") {
                j.name = str(v, key);
                if (const std::string why = badJobName(j.name); !why.empty())
                    throw InputError(fmt::format("{}: job.name \"{}\": {}; a job's name names its outputs in the output "
                                                 "directory, so it is a name, not a path (letters, digits, . _ - +, not "
                                                 "starting with .)", where(v), j.name.substr(0, 64), why));
            }
            else if (k.str() == "scene") j.scene = path(str(v, key));
            else if (k.str() == "frames") j.frames = v.is_integer() ? std::to_string(integer(v, key, 0, 1000000000)) : str(v, key);
            else if (k.str() == "seed") j.seed = std::uint64_t(integer(v, key, 0, std::numeric_limits<std::int64_t>::max()));
            else if (k.str() == "estimator") j.estimator = str(v, key);
            else if (k.str() == "spp") j.spp = std::uint32_t(integer(v, key, 1, 10000000));
            else if (k.str() == "output") j.output = path(str(v, key));
            else if (k.str() == "shard") j.shard = str(v, key);
            else if (k.str() == "define") {
                const toml::array* a = v.as_array();
                if (!a) throw InputError(fmt::format("{}: {}: expected an array of \"section.key=value\" strings", where(v), key));
                for (const toml::node& d : *a) j.defines.push_back(str(d, key));
            } else
                throw InputError(fmt::format("{}: {}: unknown key (name, scene, frames, seed, estimator, spp, output, "
                                             "shard, define)", where(v), key));
        }
        if (j.scene.empty()) throw InputError(fmt::format("{}: job without a scene", where(n)));
        if (j.name.empty())
            j.name = sanitizeJobName(fmt::format("{}{}{}", std::filesystem::path(j.scene).stem().string(),
                                                 j.frames.empty() ? "" : "-f" + j.frames, j.seed ? fmt::format("-s{}", *j.seed) : ""));
        out.push_back(std::move(j));
    }
    return result;
}

JobsFile readJobsFile(const std::filesystem::path& file) {
    return parseJobsFile(readWholeFile(file, "jobs file"), file);
}

}  // namespace accretion::cmd
