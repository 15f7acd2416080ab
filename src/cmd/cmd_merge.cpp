// accretion merge: shard outputs (render --shard i/n) into the image of one run.
#include <algorithm>
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/version.h"
#include "accretion/io/accumulation_file.h"
#include "accretion/core/output_guard.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/preview.h"
#include "accretion/render/estimators.h"
#include "accretion/scene/scene_parser.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct MergeArgs {
    std::vector<std::string> shards;  ///< shard EXRs (their .acc next to them)
    std::string output;
};

struct ShardInput {
    std::string exr;
    AccumulationFile acc;
    Shard shard;
};

/// The shards' accumulation files, sorted by shard and checked to be the
/// complete, finished parts of one run.
std::vector<ShardInput> readShards(const MergeArgs& args) {
    std::vector<ShardInput> in;
    for (const std::string& exr : args.shards) {
        const std::string accPath = std::filesystem::path(exr).replace_extension(".acc").string();
        if (!std::filesystem::exists(accPath))
            throw InputError(fmt::format("{}: missing: merge needs the accumulation file a shard writes next to its EXR",
                                         accPath));
        ShardInput s{exr, readAccumulationFile(accPath), {}};
        const nlohmann::json& h = s.acc.header;
        if (h.value("kind", "") != "shard")
            throw InputError(fmt::format("{}: a {}, not a shard's output", accPath, h.value("kind", "file")));
        s.shard = parseShard(h.value("shard", ""), accPath.c_str());
        in.push_back(std::move(s));
    }
    std::sort(in.begin(), in.end(), [](const ShardInput& a, const ShardInput& b) { return a.shard.index < b.shard.index; });
    const nlohmann::json& first = in.front().acc.header;
    const std::uint32_t count = in.front().shard.count;
    for (std::size_t k = 0; k < in.size(); ++k) {
        const nlohmann::json& h = in[k].acc.header;
        const std::string& name = in[k].exr;
        if (h.value("settings_hash", "") != first.value("settings_hash", ""))
            throw InputError(fmt::format("{}: rendered with other settings than {}: {}", name, in.front().exr,
                                         settingsDifference(first, h.value("settings", ""))));
        if (h.value("version", "") != first.value("version", ""))
            throw InputError(fmt::format("{}: rendered by accretion {}, {} by {}", name, h.value("version", "?"),
                                         in.front().exr, first.value("version", "?")));
        if (h.at("frame") != first.at("frame"))
            throw InputError(fmt::format("{}: frame {}, but {} is frame {}", name, h.at("frame").dump(), in.front().exr,
                                         first.at("frame").dump()));
        if (in[k].shard.count != count)
            throw InputError(fmt::format("{}: one of {} shards, but {} is one of {}", name, in[k].shard.count,
                                         in.front().exr, count));
        if (k > 0 && in[k].shard.index == in[k - 1].shard.index)
            throw InputError(fmt::format("{}: shard {}/{} given twice ({} too)", name, in[k].shard.index, count, in[k - 1].exr));
        if (in[k].acc.acc.nextChunk != h.at("chunks")[1].get<std::uint64_t>())
            throw InputError(fmt::format("{}: an unfinished shard (chunk {} of {})", name, in[k].acc.acc.nextChunk,
                                         h.at("chunks")[1].dump()));
    }
    if (in.size() != count) {
        std::string missing;
        for (std::uint32_t i = 0, k = 0; i < count; ++i) {
            if (k < in.size() && in[k].shard.index == i) ++k;
            else missing += fmt::format("{}{}/{}", missing.empty() ? "" : ", ", i, count);
        }
        throw InputError(fmt::format("merge: shard(s) {} missing: the image of one run needs all {}", missing, count));
    }
    return in;
}

/// The first shard's EXR with the merged lighting (Lr, its error, spp, L = Le + Lr); returns the preview.
std::vector<Vec3> mergeInto(RawExr& exr, const Accumulation& merged, const LightingImage& lighting, bool exact) {
    const char* rgb[3] = {"R", "G", "B"};
    std::size_t L[3], Le[3], Lr[3], err[3] = {0, 0, 0};
    for (int c = 0; c < 3; ++c) {
        L[c] = exr.channel(rgb[c]);
        Le[c] = exr.channel(fmt::format("Le.{}", rgb[c]));
        Lr[c] = exr.channel(fmt::format("Lr.{}", rgb[c]));
        if (!exact) err[c] = exr.channel(fmt::format("Lr_stderr.{}", rgb[c]));
    }
    const std::size_t id = exr.channel("particle.id"), rejected = exr.channel("rejected");
    const std::size_t spp = exact ? 0 : exr.channel("spp");
    std::vector<Vec3> preview(merged.pixels());
    for (std::size_t px = 0; px < merged.pixels(); ++px) {
        const bool hit = exr.bits[px * exr.channels.size() + id] != 0xffffffffu;
        for (int c = 0; c < 3; ++c) {
            exr.set(px, Lr[c], lighting.Lr[px][c]);
            if (!exact) exr.set(px, err[c], lighting.Lr_stderr[px][c]);
            if (hit) exr.set(px, L[c], exr.value(px, Le[c]) + lighting.Lr[px][c]);
            preview[px][c] = exr.value(px, L[c]);
        }
        if (!exact) exr.set(px, spp, lighting.spp[px]);
        exr.set(px, rejected, lighting.rejected[px]);
    }
    return preview;
}

void runMerge(const MergeArgs& args) {
    const std::filesystem::path output(args.output);
    if (output.extension() != ".exr" || output.stem().empty())
        throw InputError(fmt::format("command line -o {}: the merged image must be a file name ending in .exr",
                                     displayPath(output)));
    const std::filesystem::path png = std::filesystem::path(output).replace_extension(".png");
    const std::vector<ShardInput> in = readShards(args);
    OutputGuard guard;  // the merge never writes over a shard it reads
    for (const ShardInput& s : in) {
        guard.addInput(s.exr);
        guard.addInput(std::filesystem::path(s.exr).replace_extension(".acc"));
        guard.addInput(std::filesystem::path(s.exr).replace_extension(".png"));
    }
    // The shards' settings beside the image, as a render writes them: what
    // compare's worst-pixel commands render the reference's pixels with.
    const std::filesystem::path settingsFile = std::filesystem::path(output).replace_extension(".settings.toml");
    guard.check(output, "-o");
    guard.check(png, "-o (its preview)");
    guard.check(settingsFile, "-o (its settings)");
    const OutputLock lock(std::filesystem::path(output).replace_extension(".lock"));
    const nlohmann::json& first = in.front().acc.header;
    const std::uint32_t count = in.front().shard.count;

    // Sums in shard order (the same whatever order the files were given).
    Accumulation merged = in.front().acc.acc;
    for (std::size_t k = 1; k < in.size(); ++k) merged.merge(in[k].acc.acc);
    const bool exact = first.value("exact", false);
    LightingImage lighting;
    resolveLighting(merged, exact, lighting);

    RawExr exr = readRawExr(in.front().exr);
    if (exr.width != merged.width || exr.height != merged.height)
        throw InputError(fmt::format("{}: {}x{} pixels, its accumulation {}x{}", in.front().exr, exr.width, exr.height,
                                     merged.width, merged.height));
    const std::vector<Vec3> preview = mergeInto(exr, merged, lighting, exact);
    exr.attributes["accretion:shard"] = fmt::format("merged {} shards", count);
    exr.attributes["accretion:merge_version"] = std::string(version());
    exr.attributes.erase("accretion:render_time_s");
    // The preview's tone from the settings the shards were rendered with (every shard's are the same).
    const RenderSettings render = parseScene(first.at("settings").get<std::string>(), in.front().exr + " (its settings)").render;
    const PreviewTone tone = previewTone(preview, render.tonemap, render.auto_exposure, render.exposure);
    exr.attributes["accretion:preview"] = tone.describe();
    writeRawExr(output, exr);
    const std::filesystem::path base = std::filesystem::path(output).replace_extension();
    writePreviewPng(png, preview, exr.width, exr.height, tone);
    writeFileAtomic(settingsFile, first.at("settings").get<std::string>());
    double meanSpp = 0.0;
    std::size_t sampled = 0;
    for (const std::uint32_t n : merged.n) {
        meanSpp += n;
        sampled += n > 0;
    }
    if (exact) fmt::print("merged {} shards of frame {}: {} (+ {}.png)\n", count, first.at("frame").dump(), args.output, base.string());
    else
        fmt::print("merged {} shards of frame {}: {} (+ {}.png), {:.1f} samples per lit pixel\n", count,
                   first.at("frame").dump(), args.output, base.string(), sampled ? meanSpp / double(sampled) : 0.0);
}

}  // namespace

void addMergeCommand(CLI::App& app) {
    auto args = std::make_shared<MergeArgs>();
    CLI::App* cmd = app.add_subcommand("merge", "Combine the shards of a frame (render --shard i/n) into one image");
    cmd->add_option("shards", args->shards, "Shard EXRs of one frame (each with its .acc next to it)")->required();
    cmd->add_option("-o,--output", args->output, "Merged EXR (a PNG preview is written next to it)")->required();
    cmd->footer("The lighting sums of the shards are added, weighted by their sample counts, giving the image of one\n"
                "run of the same settings and seed (exact shards: bit-identical).");
    cmd->callback([args] { runMerge(*args); });
}

}  // namespace accretion::cmd
