#pragma once
#include <chrono>
#include <map>
#include <string>
#include <string_view>

namespace accretion {

/// Pass names shared by the timer, the stats file, the logs and the counters.
namespace pass {
inline constexpr std::string_view loadParticles = "loadParticles";
inline constexpr std::string_view buildLightSampler = "buildLightSampler";
inline constexpr std::string_view buildClusters = "buildClusters";
inline constexpr std::string_view traceGBuffer = "traceGBuffer";
inline constexpr std::string_view estimateLighting = "estimateLighting";
inline constexpr std::string_view presampleLightTiles = "presampleLightTiles";
inline constexpr std::string_view presampleRegirGrid = "presampleRegirGrid";
inline constexpr std::string_view generateCandidates = "generateCandidates";
inline constexpr std::string_view temporalResampling = "temporalResampling";
inline constexpr std::string_view spatialResampling = "spatialResampling";
inline constexpr std::string_view traceShadowRays = "traceShadowRays";
inline constexpr std::string_view upsampleLighting = "upsampleLighting";
inline constexpr std::string_view composeImage = "composeImage";
inline constexpr std::string_view writeOutputs = "writeOutputs";
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
