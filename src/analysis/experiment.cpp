#include "accretion/analysis/experiment.h"

#include <chrono>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/scene/scene_parser.h"

namespace accretion {
namespace {

template <class E>
bool parseEnum(const std::string& text, E& out) {
    const auto& names = EnumNames<E>::names;
    for (std::size_t i = 0; i < names.size(); ++i)
        if (names[i] == text) {
            out = static_cast<E>(i);
            return true;
        }
    return false;
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::size_t start = 0;
    for (;;) {
        const auto k = s.find(sep, start);
        out.push_back(s.substr(start, k == std::string::npos ? std::string::npos : k - start));
        if (k == std::string::npos) return out;
        start = k + 1;
    }
}

}  // namespace

std::vector<EstimatorSpec> parseEstimatorSpecs(const std::string& list, const std::string& option) {
    std::vector<EstimatorSpec> specs;
    for (const std::string& entry : split(list, ',')) {
        auto fail = [&](const std::string& why) {
            throw InputError(fmt::format("command line {} '{}': {}", option, entry, why));
        };
        if (entry.empty()) fail("empty estimator");
        const auto parts = split(entry, ':');
        EstimatorSpec spec;
        spec.label = entry;
        if (!parseEnum(parts[0], spec.kind))
            fail("unknown estimator (exact, uniform, power, tree, ris, restir)");
        spec.overrides.push_back("render.estimator=\"" + parts[0] + "\"");
        for (std::size_t k = 1; k < parts.size(); ++k) {
            const std::string& o = parts[k];
            BiasCorrection bc;
            LightSource src;
            if (o.find('=') != std::string::npos) {
                spec.overrides.push_back(o);
            } else if (o == "basic+vis") {
                spec.overrides.push_back("restir.bias_correction=\"basic\"");
                spec.overrides.push_back("restir.basic_visibility=true");
            } else if (parseEnum(o, bc)) {
                if (spec.kind != EstimatorKind::restir) fail("a bias correction applies to restir only");
                spec.overrides.push_back("restir.bias_correction=\"" + o + "\"");
            } else if (parseEnum(o, src)) {
                spec.overrides.push_back("render.source=\"" + o + "\"");
            } else {
                fail(fmt::format("unknown option '{}' (none, basic, basic+vis, pairwise, uniform, power or key=value)", o));
            }
        }
        specs.push_back(std::move(spec));
    }
    return specs;
}

Settings specSettings(const std::filesystem::path& scene, const std::vector<std::string>& base, const EstimatorSpec& spec) {
    std::vector<std::string> overrides = base;
    overrides.insert(overrides.end(), spec.overrides.begin(), spec.overrides.end());
    return loadScene(scene, overrides);
}

ExperimentRender renderForExperiment(const Settings& settings, const ParticleSource& source, std::uint32_t frame,
                                     std::uint32_t history) {
    ExperimentRender r;
    const std::uint32_t first =
        settings.render.estimator == EstimatorKind::restir ? frame - std::min(frame, history) : frame;
    Settings run = settings;  // the frames rendered, so that the pass plan keeps restir's history
    run.render.frame_start = first;
    run.render.frames = frame - first + 1;
    FrameRenderer renderer(run, source, RenderOptions{true});
    const auto start = std::chrono::steady_clock::now();
    for (std::uint32_t f = first; f <= frame; ++f) {
        FrameStats stats;
        r.image = renderer.render(f, stats);
        if (f == frame) {
            r.frameSeconds = stats.seconds;
            r.stats = std::move(stats);
        }
    }
    r.totalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
}

}  // namespace accretion
