#pragma once
#include <array>
#include <chrono>
#include <cstdint>
#include <optional>
#include <map>
#include <string>
#include <string_view>

namespace accretion {

/// The passes of a frame. Every timer, counter record, stats file, cost
/// row, coefficient file and GPU timing names a pass by passName(), and
/// parsePass() reads a name back and refuses any other: a pass renamed on
/// one side fails a join loudly instead of dropping out of it.
enum class Pass : std::uint8_t {
    loadParticles,
    buildLightSampler,
    chooseNearLights,
    buildClusters,
    traceGBuffer,
    estimateLighting,
    presampleLightTiles,
    presampleRegirGrid,
    generateCandidates,
    temporalResampling,
    spatialResampling,
    traceShadowRays,
    upsampleLighting,
    composeImage,
    writeOutputs,
};

inline constexpr std::array<std::string_view, 15> kPassNames = {
    "loadParticles",
    "buildLightSampler",
    "chooseNearLights",
    "buildClusters",
    "traceGBuffer",
    "estimateLighting",
    "presampleLightTiles",
    "presampleRegirGrid",
    "generateCandidates",
    "temporalResampling",
    "spatialResampling",
    "traceShadowRays",
    "upsampleLighting",
    "composeImage",
    "writeOutputs",
};

static_assert(kPassNames.size() == static_cast<std::size_t>(Pass::writeOutputs) + 1, "a name for every pass");

constexpr std::string_view passName(Pass p) { return kPassNames[static_cast<std::size_t>(p)]; }

/// The pass a name denotes; a repeated run's name (spatialResampling[2])
/// denotes its pass. nullopt for any other name.
std::optional<Pass> parsePass(std::string_view name);

/// The names as constants, for the timers and counters that take a name.
namespace pass {
inline constexpr std::string_view loadParticles = passName(Pass::loadParticles);
inline constexpr std::string_view buildLightSampler = passName(Pass::buildLightSampler);
inline constexpr std::string_view chooseNearLights = passName(Pass::chooseNearLights);
inline constexpr std::string_view buildClusters = passName(Pass::buildClusters);
inline constexpr std::string_view traceGBuffer = passName(Pass::traceGBuffer);
inline constexpr std::string_view estimateLighting = passName(Pass::estimateLighting);
inline constexpr std::string_view presampleLightTiles = passName(Pass::presampleLightTiles);
inline constexpr std::string_view presampleRegirGrid = passName(Pass::presampleRegirGrid);
inline constexpr std::string_view generateCandidates = passName(Pass::generateCandidates);
inline constexpr std::string_view temporalResampling = passName(Pass::temporalResampling);
inline constexpr std::string_view spatialResampling = passName(Pass::spatialResampling);
inline constexpr std::string_view traceShadowRays = passName(Pass::traceShadowRays);
inline constexpr std::string_view upsampleLighting = passName(Pass::upsampleLighting);
inline constexpr std::string_view composeImage = passName(Pass::composeImage);
inline constexpr std::string_view writeOutputs = passName(Pass::writeOutputs);
}  // namespace pass

/// Accumulated wall time per pass name, in insertion order of first use.
class PassTimer {
public:
    class Scope {
    public:
        Scope(PassTimer& timer, std::string_view name)
            : timer_(timer), name_(name), start_(std::chrono::steady_clock::now()) {}
        ~Scope() { timer_.add(name_, std::chrono::steady_clock::now() - start_); }
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;

    private:
        PassTimer& timer_;
        std::string_view name_;
        std::chrono::steady_clock::time_point start_;
    };

    Scope scope(std::string_view name) { return Scope(*this, name); }
    void add(std::string_view name, std::chrono::steady_clock::duration d);
    /// Seconds spent in a pass (0 if it never ran).
    double seconds(std::string_view name) const;
    double totalSeconds() const;
    const std::map<std::string, double, std::less<>>& all() const { return seconds_; }

private:
    std::map<std::string, double, std::less<>> seconds_;
};

}  // namespace accretion
