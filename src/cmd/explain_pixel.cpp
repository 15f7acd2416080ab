// render --pixel: the lighting of one pixel, term by term or sample by sample.
#include "explain_pixel.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/core.h>

#include "accretion/scene/estimator_table.h"
#include "accretion/lighting/shading.h"
#include "accretion/particles/particle_source.h"
#include "accretion/render/frame_renderer.h"

namespace accretion::cmd {
namespace {

constexpr std::size_t kTopTerms = 20;     ///< exact: the largest terms listed
constexpr std::size_t kSamplesShown = 64; ///< uniform / power / tree: samples listed
constexpr std::size_t kReservoirsShown = 4, kCandidatesShown = 32;  ///< ris

std::string rgb(const Vec3& v) { return fmt::format("({}, {}, {})", v.x, v.y, v.z); }
std::string light(std::uint32_t i) { return i == kNoLight ? std::string("none") : std::to_string(i); }

void printExact(const PixelTrace& t, const Vec3& Lr) {
    std::size_t visible = 0;
    DVec3 sum(0.0), shadowed(0.0);
    for (const auto& term : t.terms) {  // in light order, as the estimator summed
        if (term.visible) {
            sum += DVec3(term.value);
            ++visible;
        } else {
            shadowed += DVec3(term.value);
        }
    }
    fmt::print("exact: {} lights, {} with a non-zero term f I G, {} of them visible, {} shadowed\n", t.lightsSeen,
               t.terms.size(), visible, t.terms.size() - visible);
    fmt::print("  sum of the visible terms in light order: {} (the pixel's Lr: {})\n", rgb(Vec3(sum)),
               Vec3(sum) == Lr ? "bit-equal" : "DIFFERS");
    fmt::print("  shadowed light (the terms V removed): {}\n", rgb(Vec3(shadowed)));
    std::vector<std::size_t> order(t.terms.size());
    std::iota(order.begin(), order.end(), 0);
    const auto lum = [&](std::size_t k) { return luminance(t.terms[k].value); };
    const std::size_t shown = std::min(kTopTerms, order.size());
    std::partial_sort(order.begin(), order.begin() + shown, order.end(),
                      [&](std::size_t a, std::size_t b) { return lum(a) > lum(b) || (lum(a) == lum(b) && a < b); });
    const double total = luminance(Vec3(sum + shadowed));
    fmt::print("  the {} largest terms (luminance share of the unshadowed sum):\n", shown);
    fmt::print("  {:>9} {:>6} {:>8}  {}\n", "light", "V", "share", "f I G (RGB)");
    for (std::size_t k = 0; k < shown; ++k) {
        const auto& term = t.terms[order[k]];
        fmt::print("  {:>9} {:>6} {:>7.3f}%  {}\n", term.light, term.visible ? "1" : "0 (hit)",
                   total > 0 ? 100.0 * luminance(term.value) / total : 0.0, rgb(term.value));
    }
}

void printSamples(const PixelTrace& t) {
    fmt::print("{} light samples (one-sample estimates f I G V / pdf), the first {} listed:\n", t.samples.size(),
               std::min(kSamplesShown, t.samples.size()));
    fmt::print("  {:>5} {:>9} {:>12} {:>3}  {:<40} {}\n", "#", "light", "pdf", "V", "f I G", "estimate");
    for (std::size_t k = 0; k < t.samples.size() && k < kSamplesShown; ++k) {
        const auto& s = t.samples[k];
        fmt::print("  {:>5} {:>9} {:>12.6g} {:>3}  {:<40} {}\n", k, light(s.light), s.pdf, s.visible ? 1 : 0, rgb(s.value),
                   rgb(s.estimate));
    }
}

void printSplit(const PixelTrace& t) {
    DVec3 visible(0.0), shadowed(0.0);
    for (const auto& term : t.terms) (term.visible ? visible : shadowed) += DVec3(term.value);
    fmt::print("split: the {} nearest lights summed exactly ({} with a non-zero term f I G): {} visible, {} shadowed\n",
               t.lightsSeen, t.terms.size(), rgb(Vec3(visible)), rgb(Vec3(shadowed)));
    fmt::print("each sample is that sum plus one far light's f I G V / p_far (the estimate column: the far part)\n");
    printSamples(t);
}

void printRis(const PixelTrace& t) {
    fmt::print("{} reservoirs (RIS), the first {} listed:\n", t.reservoirs.size(), std::min(kReservoirsShown, t.reservoirs.size()));
    for (std::size_t k = 0; k < t.reservoirs.size() && k < kReservoirsShown; ++k) {
        const auto& r = t.reservoirs[k];
        fmt::print("  reservoir {}: {} candidates\n", k, r.candidates.size());
        fmt::print("    {:>9} {:>12} {:>12} {:>12}\n", "light", "pdf", "p_hat", "w");
        for (std::size_t m = 0; m < r.candidates.size() && m < kCandidatesShown; ++m) {
            const auto& c = r.candidates[m];
            fmt::print("    {:>9} {:>12.6g} {:>12.6g} {:>12.6g}\n", light(c.light), c.pdf, c.p_hat, c.w);
        }
        fmt::print("    kept y = {}, w_sum = {}, M = {}, p_hat(y) = {}, W = {}; V = {}, estimate {}\n", light(r.reservoir.y),
                   r.reservoir.w_sum, r.reservoir.M, r.reservoir.p_hat, r.reservoir.W, r.visible ? 1 : 0, rgb(r.estimate));
    }
}

void printRestir(const PixelTrace& t, const Settings& s) {
    fmt::print("restir: the pixel's reservoir after each pass\n");
    fmt::print("  {:<20} {:>9} {:>8} {:>14} {:>14}\n", "pass", "y", "M", "p_hat(y)", "W");
    for (const auto& p : t.passes)
        fmt::print("  {:<20} {:>9} {:>8} {:>14.8g} {:>14.8g}\n", p.pass.label(), light(p.reservoir.y), p.reservoir.M, p.reservoir.p_hat,
                   p.reservoir.W);
    // Why M stops growing over frames: the temporal pass caps the history's M.
    const double cap = std::floor(s.restir.m_cap * double(std::max(1u, s.render.candidates)));
    fmt::print("  M: the temporal pass keeps at most restir.m_cap x the frame's candidates of the history "
               "({} x {} = {:.0f}; docs/MODEL.md section 4), so M levels off there{}; spatial reuse then adds its "
               "neighbours' M\n",
               s.restir.m_cap, s.render.candidates, cap, s.restir.temporal ? "" : " (temporal reuse is off here)");
}

}  // namespace

void explainPixel(const Settings& settings, std::uint32_t x, std::uint32_t y, bool quiet) {
    FrameRenderer renderer(settings, ParticleSource(settings), RenderOptions{quiet});
    const std::uint32_t first = settings.render.frame_start, last = first + settings.render.frames - 1;
    const EstimatorInfo& e = estimatorInfo(settings.render.estimator);
    const bool restir = e.restirPasses();
    PixelTrace trace;
    trace.px = std::size_t(y) * settings.camera.width + x;
    FrameImage img;
    FrameStats stats;
    for (std::uint32_t frame = first; frame <= last; ++frame) {
        stats = FrameStats{};
        img = renderer.render(frame, stats, nullptr, frame == last ? &trace : nullptr);
    }
    const std::size_t px = img.window.index(x, y);  // the layers hold the window's pixels
    fmt::print("pixel ({}, {}) of frame {}, {} estimator, seed {}\n", x, y, last, enumName(settings.render.estimator),
               settings.render.seed);
    if (img.particle[px] == kNoParticle) {
        fmt::print("hit: none (background {})\nL = {}\n", rgb(img.L[px]), rgb(img.L[px]));
        return;
    }
    fmt::print("hit: particle {} at depth {}, shading normal {}\n", img.particle[px], img.depth[px], rgb(img.normal[px]));
    // What the trace recorded: the pass states of reuse, the terms of a sum,
    // RIS's reservoirs, the near field and far samples, or the samples.
    if (restir) printRestir(trace, settings);
    else if (e.sums) printExact(trace, img.lighting.Lr[px]);
    else if (e.resampling) printRis(trace);
    else if (e.nearField) printSplit(trace);
    else printSamples(trace);
    fmt::print("value (shortest round-trip decimals: the EXR's floats of a full render, bit for bit):\n");
    fmt::print("  L = {}\n  Le = {}\n  Lr = {}\n", rgb(img.L[px]), rgb(img.Le[px]), rgb(img.lighting.Lr[px]));
    if (!e.sums)
        fmt::print("  Lr_stderr = {}\n  spp = {}\n", rgb(img.lighting.Lr_stderr[px]), img.lighting.spp[px]);
    if (!img.lighting.rejected.empty() && img.lighting.rejected[px] > 0)
        fmt::print("  rejected = {} (non-finite samples)\n", img.lighting.rejected[px]);
    if (restir)
        fmt::print("  restir.W = {}, restir.M = {}, restir.light = {}, restir.p_hat = {}\n", img.reservoirs.W[px],
                   img.reservoirs.M[px], light(img.reservoirs.light[px]), img.reservoirs.p_hat[px]);
}

}  // namespace accretion::cmd
