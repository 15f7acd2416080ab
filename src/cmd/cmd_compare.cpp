// accretion compare: error metrics of an image (a GPU frame, an estimate)
// against a reference EXR; error maps; a check that the two show the same
// frame of the same scene from the same camera.
#include <cmath>
#include <memory>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/image_metrics.h"
#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/parse.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/false_colour.h"
#include "accretion/io/report_table.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CompareArgs {
    std::string image, reference, layer, channels, errorMap;
    bool json = false;
    bool allowNonFinite = false;  ///< --allow-nonfinite: measure the finite pixels, exit 0
    bool strict = false;          ///< --strict: metadata that differ are an error
};

/// "image.exr" or "reference ref.exr": which of them holds a non-finite value at pixel p.
std::string nonFiniteOwner(const CompareArgs& a, const RgbLayer& x, std::size_t p) {
    const Vec3& v = x.rgb[p];
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? "the reference " + a.reference : a.image;
}

/// The scene-defining sections of a settings TOML (what two renders of the
/// same view share whatever their estimators): particles, camera, geometry, shading.
std::vector<std::string> sceneLines(const std::string& toml) {
    std::vector<std::string> out;
    std::istringstream in(toml);
    bool keep = false;
    for (std::string line; std::getline(in, line);) {
        if (!line.empty() && line[0] == '[')
            keep = line == "[particles]" || line == "[camera]" || line == "[geometry]" || line == "[shading]";
        if (keep) out.push_back(line);
    }
    return out;
}

/// What the two images' metadata say differently: frame, scene, camera,
/// scene settings (only what both record; a GPU frame records little).
std::vector<std::string> metadataDifferences(const CompareArgs& a) {
    const auto x = readExrAttributes(a.image), r = readExrAttributes(a.reference);
    std::vector<std::string> diffs;
    auto check = [&](const char* key, const char* what) {
        const auto i = x.find(key), j = r.find(key);
        if (i != x.end() && j != r.end() && i->second != j->second)
            diffs.push_back(fmt::format("{}: {} here, {} in the reference", what, i->second.substr(0, 80), j->second.substr(0, 80)));
    };
    check("accretion:frame", "frame");
    check("accretion:scene", "scene");
    check("worldToCamera", "camera (worldToCamera)");
    check("accretion:jitter", "jitter");
    const auto i = x.find("accretion:settings"), j = r.find("accretion:settings");
    if (i != x.end() && j != r.end()) {
        const auto sx = sceneLines(i->second), sr = sceneLines(j->second);
        for (std::size_t k = 0; k < std::max(sx.size(), sr.size()); ++k) {
            const std::string lx = k < sx.size() ? sx[k] : "(none)", lr = k < sr.size() ? sr[k] : "(none)";
            if (lx != lr) {
                diffs.push_back(fmt::format("scene settings: `{}` here, `{}` in the reference", lx, lr));
                break;
            }
        }
    }
    return diffs;
}

/// --error-map OUT.exr: signed error, relative error and (with the
/// reference's Lr_stderr) z = error / stderr, per channel, and a false-colour
/// PNG of each (the channel mean) with its colour bar and scale.
void writeErrorMaps(const CompareArgs& a, const RgbLayer& x, const RgbLayer& ref) {
    const bool hasStderr = exrHasLayer(a.reference, "Lr_stderr");
    const RgbLayer sd = hasStderr ? readExrLayer(a.reference, "Lr_stderr") : RgbLayer{};
    const std::size_t n = x.rgb.size();
    std::vector<FloatChannel> ch;
    const char* rgb[3] = {"R", "G", "B"};
    std::vector<float> meanError(n), meanRel(n), meanZ(n);
    for (const char* layer : {"error", "relative", "z"}) {
        if (std::string(layer) == "z" && !hasStderr) continue;
        for (int c = 0; c < 3; ++c) {
            FloatChannel f{fmt::format("{}.{}", layer, rgb[c]), std::vector<float>(n)};
            for (std::size_t p = 0; p < n; ++p) {
                const double e = double(x.rgb[p][c]) - double(ref.rgb[p][c]);
                const double v = layer[0] == 'e' ? e
                               : layer[0] == 'r' ? e / (std::fabs(double(ref.rgb[p][c])) + kRelMseEpsilon)
                                                 : (sd.rgb[p][c] > 0.0f ? e / double(sd.rgb[p][c]) : 0.0);
                f.values[p] = float(v);
                (layer[0] == 'e' ? meanError : layer[0] == 'r' ? meanRel : meanZ)[p] += float(v / 3.0);
            }
            ch.push_back(std::move(f));
        }
    }
    writeChannelsExr(a.errorMap, x.width, x.height, ch,
                     {{"image", a.image}, {"reference", a.reference}, {"layer", a.layer.empty() ? "RGB" : a.layer}});
    const std::string base = std::filesystem::path(a.errorMap).replace_extension().string();
    const double se = symmetricScale(meanError), sr = symmetricScale(meanRel);
    writeFalseColourPng(base + ".error.png", meanError, x.width, x.height,
                        {-se, se, true, "error x - ref (mean of RGB; scale: 99th percentile)"});
    writeFalseColourPng(base + ".relative.png", meanRel, x.width, x.height,
                        {-sr, sr, true, "relative error (x - ref) / (|ref| + 0.01), mean of RGB"});
    if (hasStderr)
        writeFalseColourPng(base + ".z.png", meanZ, x.width, x.height,
                            {-4.0, 4.0, true, "z = (x - ref) / reference stderr, mean of RGB"});
    fmt::print(stderr, "accretion: error maps {} (+ {}.error.png, {}.relative.png{})\n", a.errorMap, base, base,
               hasStderr ? ", " + base + ".z.png" : std::string(", no z: the reference has no Lr_stderr"));
}

void runCompare(const CompareArgs& a) {
    if (!a.errorMap.empty()) {  // before any work: never over an input, and an EXR
        OutputGuard guard;
        guard.addInput(a.image);
        guard.addInput(a.reference);
        if (std::filesystem::path(a.errorMap).extension() != ".exr")
            throw InputError(fmt::format("command line --error-map {}: must end in .exr", a.errorMap));
        const std::string base = std::filesystem::path(a.errorMap).replace_extension().string();
        for (const std::string& out : {a.errorMap, base + ".error.png", base + ".relative.png", base + ".z.png"})
            guard.check(out, "--error-map");
    }
    std::vector<std::string> channels;
    if (!a.channels.empty()) {
        channels = splitList(a.channels, ',');
        if (channels.size() != 3)
            throw InputError(fmt::format("command line --channels {}: expected three channel names (R,G,B)", a.channels));
    }
    const RgbLayer x = channels.empty() ? readExrLayer(a.image, a.layer) : readExrChannels(a.image, channels);
    const RgbLayer ref = readExrLayer(a.reference, a.layer);
    if (x.width != ref.width || x.height != ref.height)
        throw InputError(fmt::format("{}: {}x{} pixels, but the reference {} is {}x{}", a.image, x.width, x.height,
                                     a.reference, ref.width, ref.height));
    for (const std::string& d : metadataDifferences(a)) {
        if (a.strict) throw InputError(fmt::format("{}: not the reference's view: {} (--strict)", a.image, d));
        fmt::print(stderr, "accretion: warning: {}: {}\n", a.image, d);
    }
    const ErrorMetrics m = computeErrors(x.rgb, ref.rgb);
    auto hidden = [](const char* key) { return Column{key, "", 0, "{}", "{}", false}; };
    Table t({hidden("image"), hidden("reference"), hidden("layer"), {"relMSE", "relMSE", 0, "{:.9g}"},
             {"MSE", "MSE", 0, "{:.9g}"}, {"MAPE", "MAPE", 0, "{:.9g}"}, hidden("epsilon"), hidden("pixels"),
             hidden("nonfinite_pixels")});
    t.add({a.image, a.reference, a.layer.empty() ? "RGB" : a.layer, m.relMSE, m.MSE, m.MAPE, kRelMseEpsilon,
           std::uint64_t(m.pixels), std::uint64_t(m.nonFinite)});
    if (m.nonFinite > 0) {
        std::vector<std::string> at;  // (x, y) of the first few, and where the first is
        for (const std::size_t p : m.firstNonFinite) at.push_back(fmt::format("({}, {})", p % x.width, p / x.width));
        const std::string msg = fmt::format("{} of {} pixels are NaN or infinite (at {}{}; the first in {}) and left out",
                                            m.nonFinite, x.rgb.size(), fmt::join(at, ", "), m.nonFinite > at.size() ? ", ..." : "",
                                            nonFiniteOwner(a, x, m.firstNonFinite.front()));
        if (!a.allowNonFinite || m.pixels == 0)
            throw InputError(fmt::format("{}: {}{}", a.image, msg,
                                         m.pixels == 0 ? ": no finite pixel is left to measure"
                                                       : "; give --allow-nonfinite to measure the rest"));
        fmt::print(stderr, "accretion: warning: {}\n", msg);
    }
    if (!a.errorMap.empty()) writeErrorMaps(a, x, ref);
    fmt::print("{}", a.json ? t.json()[0].dump(2) + "\n" : t.keyValues());
}

}  // namespace

void addCompareCommand(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an EXR against a reference EXR (the second image)");
    cmd->add_option("image", args->image, "Image (EXR: a GPU frame or an estimate)")->required();
    cmd->add_option("reference", args->reference, "Reference (EXR)")->required();
    cmd->add_option("--layer", args->layer, "Channels compared: RGB (default) or a layer such as Lr");
    cmd->add_option("--channels", args->channels, "The image's three channels, e.g. color.r,color.g,color.b (a GPU frame's names)");
    cmd->add_option("--error-map", args->errorMap,
                    "Write signed, relative and z errors to this EXR, and false-colour PNGs of each beside it");
    cmd->add_flag("--strict", args->strict, "A different frame, scene, camera or scene settings is an error (else a warning)");
    cmd->add_flag("--json", args->json, "Machine-readable output");
    cmd->add_flag("--allow-nonfinite", args->allowNonFinite,
                  "Measure the finite pixels when some are NaN or infinite (counted, first one located; else exit 1)");
    cmd->footer("relMSE = mean (x-ref)^2/(ref^2+1e-2); MSE = mean (x-ref)^2; MAPE = mean |x-ref|/(|ref|+1e-2);\n"
                "means over pixels and RGB channels.");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace accretion::cmd
