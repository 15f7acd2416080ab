// accretion compare: error metrics of an image (a GPU frame, an estimate)
// against a reference EXR; error maps; a check that the two show the same
// frame of the same scene from the same camera.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "accretion/analysis/flip.h"
#include "accretion/analysis/image_metrics.h"
#include "accretion/analysis/view_check.h"
#include "accretion/core/atomic_file.h"
#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/parse.h"
#include "accretion/core/read_file.h"
#include "accretion/io/exr_output.h"
#include "accretion/io/false_colour.h"
#include "accretion/io/plot.h"
#include "accretion/io/report_table.h"
#include "commands.h"

namespace accretion::cmd {
namespace {

struct CompareArgs {
    std::string image, reference, layer, channels, errorMap;
    std::string flip = "hdr";     ///< --flip hdr | ldr | none
    double ppd = FlipOptions{}.ppd;
    std::string frames;           ///< --frames A:B: image and reference are {frame} patterns
    std::string csv;              ///< --csv FILE: the per-frame table of a sequence (+ FILE.png plot)
    bool json = false;
    bool allowNonFinite = false;  ///< --allow-nonfinite: measure the finite pixels, exit 0
    bool strict = false;          ///< --strict: metadata that differ are an error
    double tolerance = kAgreementTolerance;  ///< --tolerance: relative tolerance of the pixel agreement
};

/// The FLIP variant's name, as tables, maps and plots show it.
std::string flipName(const CompareArgs& a) { return a.flip == "ldr" ? "LDR-FLIP" : a.flip == "hdr" ? "HDR-FLIP" : "FLIP (off)"; }

/// Two images on the pixels both hold: the overlap of their data windows.
struct Pair {
    std::string image, reference;
    RgbLayer x, ref;
    int x0 = 0, y0 = 0;
    std::uint32_t w = 0, h = 0;
    std::vector<Vec3> xs, rs;  ///< the overlap's pixels of each
    bool partial() const { return !(x.whole() && ref.whole()); }
    /// "(x, y)" of the overlap's pixel p.
    std::string at(std::size_t p) const { return fmt::format("({}, {})", x0 + int(p % w), y0 + int(p / w)); }
};

Pair loadPair(const CompareArgs& a, const std::string& image, const std::string& reference,
              const std::vector<std::string>& channels) {
    Pair p{image, reference, channels.empty() ? readExrLayer(image, a.layer) : readExrChannels(image, channels),
           readExrLayer(reference, a.layer)};
    if (p.x.width != p.ref.width || p.x.height != p.ref.height)
        throw InputError(fmt::format("{}: {}x{} pixels, but the reference {} is {}x{}", image, p.x.width, p.x.height, reference,
                                     p.ref.width, p.ref.height));
    const int x1 = std::min(p.x.x0 + int(p.x.dataWidth), p.ref.x0 + int(p.ref.dataWidth));
    const int y1 = std::min(p.x.y0 + int(p.x.dataHeight), p.ref.y0 + int(p.ref.dataHeight));
    p.x0 = std::max(p.x.x0, p.ref.x0);
    p.y0 = std::max(p.x.y0, p.ref.y0);
    if (x1 <= p.x0 || y1 <= p.y0)
        throw InputError(fmt::format("{}: its data window ({}x{} at ({}, {})) and the reference's ({}x{} at ({}, {})) share no pixel",
                                     image, p.x.dataWidth, p.x.dataHeight, p.x.x0, p.x.y0, p.ref.dataWidth, p.ref.dataHeight,
                                     p.ref.x0, p.ref.y0));
    p.w = std::uint32_t(x1 - p.x0);
    p.h = std::uint32_t(y1 - p.y0);
    p.xs = p.x.window(p.x0, p.y0, p.w, p.h);
    p.rs = p.ref.window(p.x0, p.y0, p.w, p.h);
    return p;
}

/// "image.exr" or "reference ref.exr": which of them holds a non-finite value at overlap pixel q.
std::string nonFiniteOwner(const Pair& p, std::size_t q) {
    const Vec3& v = p.xs[q];
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? "the reference " + p.reference : p.image;
}

double fraction(std::size_t k, std::size_t n) { return n ? double(k) / double(n) : 0.0; }

/// The metrics of one pair: relMSE, MSE, MAPE and FLIP over the finite pixels.
struct Comparison {
    ErrorMetrics m;
    double flip = std::numeric_limits<double>::quiet_NaN();  ///< mean FLIP (--flip none: NaN)
    std::vector<float> flipMap;                              ///< per overlap pixel (non-finite pixels: 0)
    HdrFlip hdr;                                             ///< hdr: the exposure range used
};

Comparison measure(const CompareArgs& a, const Pair& p) {
    Comparison c;
    c.m = computeErrors(p.xs, p.rs, nullptr, kRelMseEpsilon, a.tolerance);
    if (c.m.nonFinite > 0) {
        std::vector<std::string> at;  // (x, y) of the first few, and where the first is
        for (const std::size_t q : c.m.firstNonFinite) at.push_back(p.at(q));
        const std::string msg = fmt::format("{} of {} pixels are NaN or infinite (at {}{}; the first in {}) and left out",
                                            c.m.nonFinite, p.xs.size(), fmt::join(at, ", "), c.m.nonFinite > at.size() ? ", ..." : "",
                                            nonFiniteOwner(p, c.m.firstNonFinite.front()));
        if (!a.allowNonFinite || c.m.pixels == 0)
            throw InputError(fmt::format("{}: {}{}", p.image, msg,
                                         c.m.pixels == 0 ? ": no finite pixel is left to measure"
                                                         : "; give --allow-nonfinite to measure the rest"));
        fmt::print(stderr, "accretion: warning: {}\n", msg);
    }
    if (a.flip == "none") return c;
    // FLIP filters neighbourhoods: a non-finite pixel enters as black and is left out of the mean.
    std::vector<Vec3> x = p.xs, r = p.rs;
    std::vector<bool> finite(x.size());
    for (std::size_t q = 0; q < x.size(); ++q) {
        finite[q] = std::isfinite(x[q].x + x[q].y + x[q].z) && std::isfinite(r[q].x + r[q].y + r[q].z);
        if (!finite[q]) x[q] = r[q] = Vec3(0.0f);
    }
    const FlipOptions opt{a.ppd};
    if (a.flip == "hdr") {
        c.hdr = hdrFlip(r, x, p.w, p.h, opt);
        c.flipMap = c.hdr.error;
    } else {  // ldr: the images as a display shows them at exposure 0 (clamped, sRGB-encoded)
        for (std::vector<Vec3>* img : {&x, &r})
            for (Vec3& v : *img)
                for (int k = 0; k < 3; ++k) v[k] = linearToSrgb(std::clamp(v[k], 0.0f, 1.0f));
        c.flipMap = ldrFlip(r, x, p.w, p.h, opt);
    }
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t q = 0; q < x.size(); ++q)
        if (finite[q]) {
            sum += c.flipMap[q];
            ++n;
        } else {
            c.flipMap[q] = 0.0f;
        }
    c.flip = n ? sum / double(n) : 0.0;
    return c;
}

/// --error-map OUT.exr: signed error, relative error, (with the
/// reference's Lr_stderr) z = error / stderr per channel, and FLIP, over the
/// pixels compared (the EXR's data window); a false-colour PNG of each (the
/// channel mean) with its colour bar and scale.
void writeErrorMaps(const CompareArgs& a, const Pair& p, const Comparison& cmp) {
    const bool hasStderr = exrHasLayer(a.reference, "Lr_stderr");
    const std::vector<Vec3> sd = hasStderr ? readExrLayer(a.reference, "Lr_stderr").window(p.x0, p.y0, p.w, p.h) : std::vector<Vec3>{};
    const std::size_t n = p.xs.size();
    std::vector<FloatChannel> ch;
    const char* rgb[3] = {"R", "G", "B"};
    std::vector<float> meanError(n), meanRel(n), meanZ(n);
    for (const char* layer : {"error", "relative", "z"}) {
        if (std::string(layer) == "z" && !hasStderr) continue;
        for (int c = 0; c < 3; ++c) {
            FloatChannel f{fmt::format("{}.{}", layer, rgb[c]), std::vector<float>(n)};
            for (std::size_t q = 0; q < n; ++q) {
                const double e = double(p.xs[q][c]) - double(p.rs[q][c]);
                const double v = layer[0] == 'e' ? e
                               : layer[0] == 'r' ? e / (std::fabs(double(p.rs[q][c])) + kRelMseEpsilon)
                                                 : (sd[q][c] > 0.0f ? e / double(sd[q][c]) : 0.0);
                f.values[q] = float(v);
                (layer[0] == 'e' ? meanError : layer[0] == 'r' ? meanRel : meanZ)[q] += float(v / 3.0);
            }
            ch.push_back(std::move(f));
        }
    }
    if (!cmp.flipMap.empty()) ch.push_back({"flip", cmp.flipMap});
    writeChannelsExr(a.errorMap, p.w, p.h, ch,
                     {{"image", a.image}, {"reference", a.reference}, {"layer", a.layer.empty() ? "RGB" : a.layer},
                      {"flip", a.flip}, {"ppd", fmt::format("{}", a.ppd)}},
                     DataWindow{p.x0, p.y0, p.x.width, p.x.height});
    const std::string base = std::filesystem::path(a.errorMap).replace_extension().string();
    const double se = symmetricScale(meanError), sr = symmetricScale(meanRel);
    writeFalseColourPng(base + ".error.png", meanError, p.w, p.h,
                        {-se, se, true, "error x - ref, radiance (mean of RGB; scale: 99th percentile of |error|)"});
    writeFalseColourPng(base + ".relative.png", meanRel, p.w, p.h,
                        {-sr, sr, true, "relative error (x - ref) / (|ref| + 0.01), mean of RGB"});
    if (hasStderr)
        writeFalseColourPng(base + ".z.png", meanZ, p.w, p.h,
                            {-4.0, 4.0, true, "z = (x - ref) / reference stderr, mean of RGB"});
    if (!cmp.flipMap.empty())
        writeFalseColourPng(base + ".flip.png", cmp.flipMap, p.w, p.h,
                            {0.0, 1.0, false, fmt::format("{} (0: no visible difference, 1: the largest; {:.0f} pixels per degree)",
                                                          flipName(a), a.ppd)});
    fmt::print(stderr, "accretion: error maps {} (+ {}.error.png, {}.relative.png{}{})\n", a.errorMap, base, base,
               hasStderr ? ", " + base + ".z.png" : std::string(", no z: the reference has no Lr_stderr"),
               cmp.flipMap.empty() ? std::string() : ", " + base + ".flip.png");
}

/// Metadata differences: a warning each, or (--strict) an error.
/// The view check of the pair; returns the reference's attributes (read once).
std::map<std::string, std::string> checkMetadata(const CompareArgs& a, const std::string& image, const std::string& reference) {
    std::map<std::string, std::string> attributes = readExrAttributes(reference);
    reportViewCheck(checkView(readExrAttributes(image), attributes), image, reference, a.strict);
    return attributes;
}

void checkFlipOption(const CompareArgs& a) {
    if (a.flip != "hdr" && a.flip != "ldr" && a.flip != "none")
        throw InputError(fmt::format("command line --flip {}: expected hdr, ldr or none", a.flip));
    if (!(a.ppd > 0.0 && a.ppd < 1e4)) throw InputError(fmt::format("command line --ppd {}: expected pixels per degree in (0, 1e4)", a.ppd));
}

std::vector<std::string> parseChannels(const CompareArgs& a) {
    if (a.channels.empty()) return {};
    std::vector<std::string> channels = splitList(a.channels, ',');
    if (channels.size() != 3)
        throw InputError(fmt::format("command line --channels {}: expected three channel names (R,G,B)", a.channels));
    return channels;
}

/// The reference's pixels that the image misses most (relative squared
/// error summed over channels, as relMSE weighs them), each with the command
/// that explains it light by light: `render --pixel` on the reference's own
/// settings (its .settings.toml beside it, else its scene and estimator).
void printWorstPixels(const Pair& p, const std::map<std::string, std::string>& attrs, std::size_t count) {
    std::vector<std::pair<double, std::size_t>> worst;
    for (std::size_t q = 0; q < p.xs.size(); ++q) {
        double e = 0.0;
        for (int c = 0; c < 3; ++c) {
            const double d = double(p.xs[q][c]) - p.rs[q][c];
            e += d * d / (double(p.rs[q][c]) * p.rs[q][c] + kRelMseEpsilon);
        }
        if (std::isfinite(e) && e > 0.0) worst.emplace_back(e, q);
    }
    count = std::min(count, worst.size());
    std::partial_sort(worst.begin(), worst.begin() + std::ptrdiff_t(count), worst.end(), std::greater<>());
    if (count == 0) return;
    auto attr = [&](const char* key) { return attrs.count(key) ? attrs.at(key) : std::string(); };
    // The settings file of the run that wrote the reference: "ref.exr" ->
    // "ref.settings.toml", "ref.0003.exr" (a {frame} run) -> "ref.settings.toml".
    const std::string stem = std::filesystem::path(p.reference).replace_extension().string();
    const std::size_t digits = stem.size() - std::min(stem.size(), stem.find_last_not_of("0123456789") + 1);
    std::vector<std::string> candidates = {stem + ".settings.toml"};
    if (digits >= 4 && digits < stem.size() && std::string_view("._-").find(stem[stem.size() - digits - 1]) != std::string_view::npos)
        candidates.push_back(stem.substr(0, stem.size() - digits - 1) + ".settings.toml");
    // A settings file is the reference's only if its text is the settings
    // the reference records: a later run to the same name rewrites it.
    std::string scene, why = " (the reference names no scene to explain them)";
    bool stale = false;
    for (const std::string& c : candidates) {
        if (!scene.empty() || !std::filesystem::exists(c)) continue;
        if (!attr("accretion:settings").empty() && readWholeFile(c, "settings file") == attr("accretion:settings")) {
            scene = c;
        } else {
            stale = true;
            why = fmt::format(" ({} is not the settings the reference records: a later run rewrote it)", displayPath(c));
        }
    }
    if (scene.empty() && !stale && !attr("accretion:scene").empty())  // no settings file: the scene, without its -D overrides
        scene = fmt::format("{} --estimator {} --seed {}", attr("accretion:scene"), attr("accretion:estimator"), attr("accretion:seed"));
    fmt::print("worst pixels (relative squared error){}:\n", scene.empty() ? why : "");
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t q = worst[k].second;
        const int x = p.x0 + int(q % p.w), y = p.y0 + int(q / p.w);
        if (scene.empty()) fmt::print("  {:>10.4g}  ({}, {})\n", worst[k].first, x, y);
        else
            fmt::print("  {:>10.4g}  accretion render {} --frames {} --pixel {},{}\n", worst[k].first, scene,
                       attr("accretion:frame").empty() ? "0" : attr("accretion:frame"), x, y);
    }
}

void runCompareOne(const CompareArgs& a) {
    if (!a.errorMap.empty()) {  // before any work: never over an input, and an EXR
        OutputGuard guard;
        guard.addInput(a.image);
        guard.addInput(a.reference);
        if (std::filesystem::path(a.errorMap).extension() != ".exr")
            throw InputError(fmt::format("command line --error-map {}: must end in .exr", a.errorMap));
        const std::string base = std::filesystem::path(a.errorMap).replace_extension().string();
        for (const std::string& out : {a.errorMap, base + ".error.png", base + ".relative.png", base + ".z.png", base + ".flip.png"})
            guard.check(out, "--error-map");
    }
    const Pair p = loadPair(a, a.image, a.reference, parseChannels(a));
    const auto referenceAttributes = checkMetadata(a, a.image, a.reference);
    if (p.partial())
        fmt::print(stderr, "accretion: compared the {}x{} pixels at ({}, {}) that both data windows hold (of {}x{})\n", p.w, p.h,
                   p.x0, p.y0, p.x.width, p.x.height);
    const Comparison c = measure(a, p);
    auto hidden = [](const char* key) { return Column{key, "", 0, "{}", "{}", false}; };
    Table t({hidden("image"), hidden("reference"), hidden("layer"), {"relMSE", "relMSE", 0, "{:.9g}"},
             {"MSE", "MSE", 0, "{:.9g}"}, {"MAPE", "MAPE", 0, "{:.9g}"},
             {"flip", flipName(a), 0, "{:.6f}"}, hidden("flip_variant"), hidden("ppd"),
             hidden("epsilon"), hidden("pixels"), hidden("nonfinite_pixels"), hidden("window"),
             hidden("lit_pixels"), {"identical", "identical lit pixels (fraction)", 0, "{:.6f}"},
             {"within_tolerance", "lit pixels within tolerance (fraction)", 0, "{:.6f}"},
             hidden("tolerance")});
    t.add({a.image, a.reference, a.layer.empty() ? "RGB" : a.layer, c.m.relMSE, c.m.MSE, c.m.MAPE, c.flip, a.flip, a.ppd,
           kRelMseEpsilon, std::uint64_t(c.m.pixels), std::uint64_t(c.m.nonFinite),
           fmt::format("{}x{}+{}+{}", p.w, p.h, p.x0, p.y0), std::uint64_t(c.m.lit), fraction(c.m.identical, c.m.lit),
           fraction(c.m.withinTolerance, c.m.lit), a.tolerance});
    if (!a.errorMap.empty()) writeErrorMaps(a, p, c);
    fmt::print("{}", a.json ? t.json()[0].dump(2) + "\n" : t.keyValues());
    if (!a.json) printWorstPixels(p, referenceAttributes, 5);
    if (a.flip == "hdr" && !a.json)
        fmt::print("HDR-FLIP exposures: {} from {:.4f} to {:.4f} stops (ACES)\n", c.hdr.exposures, c.hdr.startExposure,
                   c.hdr.stopExposure);
}

/// The frame-to-frame change of the error, relative to the reference:
/// mean ((e_t - e_t-1)^2 / (ref_t^2 + eps)) over the pixels whose reference
/// sees the same particle in both frames (when ids are given; else every
/// pixel), and the fraction of such pixels. NaN, NaN for the first frame.
std::pair<double, double> flickerOf(const std::vector<Vec3>& error, const std::vector<Vec3>& lastError,
                                    const std::vector<std::uint32_t>& ids, const std::vector<std::uint32_t>& lastIds,
                                    const std::vector<Vec3>& reference) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (lastError.empty() || lastError.size() != error.size()) return {nan, nan};
    const bool byParticle = !ids.empty() && ids.size() == lastIds.size();
    double sum = 0.0;
    std::size_t n = 0, pixels = 0;
    for (std::size_t q = 0; q < error.size(); ++q) {
        if (byParticle && (ids[q] != lastIds[q] || ids[q] == 0xffffffffu)) continue;
        ++pixels;
        for (int ch = 0; ch < 3; ++ch) {
            const double d = double(error[q][ch]) - double(lastError[q][ch]), r = reference[q][ch];
            if (!std::isfinite(d)) continue;
            sum += d * d / (r * r + kRelMseEpsilon);
            ++n;
        }
    }
    return {n ? sum / double(n) : 0.0, double(pixels) / double(error.size())};
}

void plotSequence(const CompareArgs& a, const std::string& png, std::uint64_t frames);

/// compare 'gpu.{frame}.exr' 'ref.{frame}.exr' --frames A:B --csv FILE:
/// each frame's metrics, and the frame-to-frame change of the error
/// (flicker: mean ((e_t - e_t-1)^2 / (ref_t^2 + eps)) over the pixels whose
/// reference sees the same particle in both frames, when it has a
/// particle.id channel; the fraction of such pixels is `tracked`), what
/// temporal reuse makes or hides, as a CSV and a plot.
void runCompareSequence(const CompareArgs& a) {
    const auto [first, end] = parseHalfOpen(a.frames, "--frames");
    for (const std::string* pattern : {&a.image, &a.reference})
        if (pattern->find("{frame}") == std::string::npos)
            throw InputError(fmt::format("command line --frames {}: {} has no {{frame}} pattern", a.frames, *pattern));
    if (a.csv.empty()) throw InputError(fmt::format("command line --frames {}: give --csv FILE for the per-frame table", a.frames));
    if (!a.errorMap.empty()) throw InputError("command line --error-map: maps one pair of images; give it without --frames");
    if (std::filesystem::path(a.csv).extension() != ".csv")
        throw InputError(fmt::format("command line --csv {}: must end in .csv (its plot goes beside it as .png)", a.csv));
    const std::string png = std::filesystem::path(a.csv).replace_extension(".png").string();
    OutputGuard guard;
    std::vector<std::pair<std::string, std::string>> files;
    for (std::uint64_t f = first; f < end; ++f) {  // each pair found before the next is named: no list of 4e9 names
        files.push_back({expandPattern(a.image, "", std::uint32_t(f)), expandPattern(a.reference, "", std::uint32_t(f))});
        for (const std::string& file : {files.back().first, files.back().second}) {
            if (!std::filesystem::is_regular_file(file))
                throw InputError(fmt::format("{}: not found (frame {} of --frames {})", file, f, a.frames));
            guard.addInput(file);
        }
    }
    guard.check(a.csv, "--csv");
    guard.check(png, "--csv (its plot)");
    const std::vector<std::string> channels = parseChannels(a);
    Table t({{"frame", "frame", 6}, {"relMSE", "relMSE", 13, "{:.6g}", "{:.9g}"}, {"MSE", "MSE", 13, "{:.6g}", "{:.9g}"},
             {"MAPE", "MAPE", 11, "{:.6g}", "{:.9g}"}, {"flip", flipName(a), 10, "{:.5f}", "{:.6f}"},
             {"flicker", "flicker", 13, "{:.6g}", "{:.9g}"}, {"tracked", "tracked", 8, "{:.3f}", "{:.6f}"},
             {"nonfinite_pixels", "nonfinite", 9},
             {"image", "", 0, "{}", "{}", false}, {"reference", "", 0, "{}", "{}", false}});
    std::vector<Vec3> lastError;
    std::vector<std::uint32_t> lastIds;
    for (std::size_t k = 0; k < files.size(); ++k) {
        const auto& [image, reference] = files[k];
        const Pair p = loadPair(a, image, reference, channels);
        checkMetadata(a, image, reference);
        const Comparison c = measure(a, p);
        std::vector<Vec3> error(p.xs.size());
        for (std::size_t q = 0; q < error.size(); ++q) error[q] = p.xs[q] - p.rs[q];
        // Which particle the reference sees at each pixel: flicker compares a
        // pixel's error with its previous error only where the same particle
        // is seen in both frames (a moving camera or disk moves the rest).
        std::vector<std::uint32_t> ids;
        if (p.ref.whole() && p.x.whole()) ids = readExrUintChannel(reference, "particle.id");
        const auto [flicker, tracked] = flickerOf(error, lastError, ids, lastIds, p.rs);
        lastError = std::move(error);
        lastIds = std::move(ids);
        t.add({first + k, c.m.relMSE, c.m.MSE, c.m.MAPE, c.flip, flicker, tracked, std::uint64_t(c.m.nonFinite), image, reference});
        if (!a.json) fmt::print(stderr, "accretion: frame {}: relMSE {:.4g}, FLIP {:.4f}\n", first + k, c.m.relMSE, c.flip);
    }
    writeFileAtomic(a.csv, t.csv());
    plotSequence(a, png, end - first);
    fmt::print("{}", a.json ? t.json().dump(2) + "\n" : t.console());
    fmt::print("per-frame table: {} (plot: {})\n", a.csv, png);
}

/// The sequence's plot: relMSE and flicker by frame, FLIP on the right axis.
void plotSequence(const CompareArgs& a, const std::string& png, std::uint64_t frames) {
    const bool flip = a.flip != "none";
    std::string script = fmt::format(
        "set datafile separator ','\nset key outside top center horizontal box\nset grid\n"
        "set xlabel 'frame'\nset xtics {}\nset ylabel 'relMSE, flicker (relative squared error, unitless)'\nset logscale y\n"
        "set title {}\n",
        frames <= 20 ? "1" : "autofreq",
        gnuplotQuote(fmt::format("{} against {}\nflicker: relMSE of the error's change from the previous frame, where the same "
                                 "particle is seen", a.image, a.reference)));
    if (flip) script += fmt::format("set y2label '{} (mean, 0 to 1)'\nset y2range [0:*]\nset y2tics\nset ytics nomirror\n", flipName(a));
    script += fmt::format("plot {} using 1:2 with linespoints title 'relMSE', '' using 1:6 with linespoints title 'flicker'",
                          gnuplotQuote(a.csv));
    if (flip) script += fmt::format(", '' using 1:5 axes x1y2 with linespoints title '{} (right axis)'", flipName(a));
    plotPng(png, script + "\n", 900, 560);
}

void runCompare(const CompareArgs& a) {
    checkFlipOption(a);
    if (a.frames.empty()) {
        if (!a.csv.empty()) throw InputError("command line --csv: the per-frame table of a sequence; give --frames A:B too");
        runCompareOne(a);
    } else {
        runCompareSequence(a);
    }
}

}  // namespace

void addCompareCommand(CLI::App& app) {
    auto args = std::make_shared<CompareArgs>();
    CLI::App* cmd = app.add_subcommand("compare", "Error metrics of an EXR against a reference EXR (the second image)");
    cmd->add_option("image", args->image, "Image (EXR: a GPU frame or an estimate)")->required();
    cmd->add_option("reference", args->reference, "Reference (EXR)")->required();
    cmd->add_option("--layer", args->layer, "Channels compared: RGB (default), a layer such as Lr, or one channel such as spp");
    cmd->add_option("--channels", args->channels, "The image's three channels, e.g. color.r,color.g,color.b (a GPU frame's names)");
    cmd->add_option("--error-map", args->errorMap,
                    "Write signed, relative and z errors to this EXR, and false-colour PNGs of each beside it");
    cmd->add_option("--flip", args->flip,
                    "Perceptual metric: hdr (HDR-FLIP over the reference's exposure range, default), ldr (LDR-FLIP of the "
                    "images clamped to [0, 1] as sRGB) or none");
    cmd->add_option("--ppd", args->ppd, "FLIP observer: pixels per degree (default 67: a 0.7 m wide 4K monitor at 0.7 m)");
    cmd->add_option("--frames", args->frames,
                    "A:B: image and reference are {frame} patterns (e.g. 'gpu.{frame}.exr'); one row per frame, with the "
                    "frame-to-frame change of the error (flicker)");
    cmd->add_option("--csv", args->csv, "With --frames: the per-frame table (CSV), and a plot beside it (.png)");
    cmd->add_option("--tolerance", args->tolerance,
                    "Relative tolerance of the pixel agreement (pixels within tolerance: |x-ref| <= tol |ref| in each channel)")
        ->check(finiteIn(0.0, 1e30));
    cmd->add_flag("--strict", args->strict, "A different frame, scene, camera or scene settings is an error (else a warning)");
    cmd->add_flag("--json", args->json, "Machine-readable output");
    cmd->add_flag("--allow-nonfinite", args->allowNonFinite,
                  "Measure the finite pixels when some are NaN or infinite (counted, first one located; else exit 1)");
    cmd->footer("relMSE = mean (x-ref)^2/(ref^2+1e-2); MSE = mean (x-ref)^2; MAPE = mean |x-ref|/(|ref|+1e-2);\n"
                "means over pixels and RGB channels, over the pixels both data windows hold.\n"
                "FLIP: Andersson et al. 2020 (LDR) and 2021 (HDR), mean over the pixels.");
    cmd->callback([args] { runCompare(*args); });
}

}  // namespace accretion::cmd
