// accretion import-gpu: a frame of accretion-optix (the GPU twin) as the EXR
// and previews `render` writes, so that compare, bias and merge read it like
// any frame.
#include <algorithm>
#include <filesystem>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/gpu_frame_file.h"
#include "accretion/io/preview.h"
#include "accretion/render/gbuffer.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct ImportArgs {
    std::vector<std::string> inputs;
    std::string outDir;
};

/// render's frame image of a GPU frame: the Monte Carlo estimators' standard
/// error, sample count and rejections where the frame has them (uniform,
/// power), else exact-style lighting (restir's estimate is what it is).
FrameImage frameImage(const GpuFrame& g) {
    FrameImage img;
    img.width = g.width;
    img.height = g.height;
    img.window = PixelWindow::whole(g.width, g.height);
    img.camera = g.camera;
    img.L = g.L;
    img.Le = g.Le;
    img.normal = g.normal;
    img.depth = g.depth;
    img.particle = g.particle;
    const std::size_t n = std::size_t(g.width) * g.height;
    img.lighting.Lr = g.Lr;
    img.lighting.Lr_stderr = g.Lr_stderr.empty() ? std::vector<Vec3>(n, Vec3(0.0f)) : g.Lr_stderr;
    img.lighting.spp = g.spp.empty() ? std::vector<float>(n, 0.0f) : g.spp;
    img.lighting.rejected = g.rejected.empty() ? std::vector<float>(n, 0.0f) : g.rejected;
    return img;
}

ToneMap toneOf(const GpuFrame& g) {
    ToneMap t = ToneMap::filmic;
    if (auto it = g.metadata.find("tonemap"); it != g.metadata.end()) parseEnum(it->second, t);
    return t;
}

void runImport(const ImportArgs& a) {
    // Every input read and checked before anything is written.
    std::vector<GpuFrame> frames;
    for (const std::string& in : a.inputs) {
        frames.push_back(readGpuFrame(in));
        if (!frames.back().complete())
            throw InputError(fmt::format("{}: holds Lr alone (accretion-optix --lr-only, a frame for `bias --gpu-frames`); "
                                         "import-gpu needs every plane", in));
    }
    OutputGuard guard;
    for (const std::string& in : a.inputs) guard.addInput(in);
    std::vector<std::string> outputs;
    for (const std::string& in : a.inputs) {
        std::filesystem::path p(in);
        const std::filesystem::path dir = a.outDir.empty() ? p.parent_path() : std::filesystem::path(a.outDir);
        const std::string base = (dir / p.stem()).string();
        if (const auto k = std::find(outputs.begin(), outputs.end(), base); k != outputs.end())
            throw InputError(fmt::format("{}: would be written to {}.exr, as {} is: outputs would collide (import them into "
                                         "separate folders, or rename one)", in, base, a.inputs[std::size_t(k - outputs.begin())]));
        for (const char* ext : {".exr", ".png", ".Lr.png"}) guard.check(base + ext, "output");
        outputs.push_back(base);
    }
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const GpuFrame& g = frames[k];
        const FrameImage img = frameImage(g);
        OutputMetadata meta(g.metadata.begin(), g.metadata.end());
        const std::string& base = outputs[k];
        const PreviewTone tone = previewTone(img.L, toneOf(g), true, 0.0);
        meta["preview"] = tone.describe();
        writeFrameExr(base + ".exr", img, !g.Lr_stderr.empty(), meta);  // uniform / power: Lr_stderr and spp
        writePreviewPng(base + ".png", img.L, g.width, g.height, tone);
        writePreviewPng(base + ".Lr.png", img.lighting.Lr, g.width, g.height,
                        previewTone(img.lighting.Lr, toneOf(g), true, 0.0));
        fmt::print("{}: {}.exr ({}x{}, frame {}, {})\n", a.inputs[k], base, g.width, g.height, g.frame,
                   g.metadata.count("device") ? g.metadata.at("device") : "GPU");
    }
}

}  // namespace

void addImportGpuCommand(CLI::App& app) {
    auto args = std::make_shared<ImportArgs>();
    CLI::App* cmd = app.add_subcommand("import-gpu", "Turn frames of accretion-optix (the OptiX twin, .gpuframe) into render's EXR and previews");
    cmd->add_option("frames", args->inputs, "The .gpuframe files")->required()->check(CLI::ExistingFile);
    cmd->add_option("-o,--out", args->outDir, "Folder of the EXRs (default: beside each input)");
    cmd->callback([args] { runImport(*args); });
}

}  // namespace accretion::cmd
