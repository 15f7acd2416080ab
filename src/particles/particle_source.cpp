#include "accretion/particles/particle_source.h"

#include <filesystem>

#include <fmt/format.h>

#include "accretion/core/error.h"

#include "accretion/particles/disk_generator.h"
#include "accretion/particles/particle_file.h"

namespace accretion {

ParticleSource::ParticleSource(const Settings& settings)
    : particles_(settings.particles), albedo_(settings.shading.albedo) {
    if (particles_.file.empty()) {
        const auto [lo, hi] = diskTemperatureRange(particles_);
        blackbody_ = std::make_shared<const BlackbodyTable>(lo, hi);
    }
}

ParticleSource ParticleSource::fixed(Particles particles) {
    ParticleSource s;
    s.fixed_ = std::move(particles);
    return s;
}

bool ParticleSource::isStatic() const {
    if (fixed_) return true;
    if (!particles_.file.empty()) return particles_.file.find("{frame}") == std::string::npos;
    return particles_.time_step == 0.0 || particles_.gm == 0.0;
}

std::vector<std::filesystem::path> ParticleSource::checkFiles(std::uint32_t first, std::uint32_t end) const {
    std::vector<std::filesystem::path> files;
    if (fixed_ || particles_.file.empty()) return files;
    if (particles_.file.find("{frame}") == std::string::npos) {
        inspectParticleFile(particles_.file);
        files.emplace_back(particles_.file);
        return files;
    }
    std::optional<ParticleFileInfo> firstInfo;
    std::filesystem::path firstFile;
    // The run's frames must exist; the neighbours on either side give
    // velocities when they exist.
    const std::uint64_t lo = first > 0 ? first - 1 : first, hi = std::uint64_t(end) + 1;
    for (std::uint64_t f = lo; f < hi; ++f) {
        const std::filesystem::path file = expandPattern(particles_.file, "", std::uint32_t(f));
        const bool inRun = f >= first && f < end;
        if (!inRun && !std::filesystem::exists(file)) continue;
        if (inRun && !std::filesystem::exists(file))
            throw InputError(fmt::format("{}: particle file of frame {} not found (frames {}..{} of this run are checked "
                                         "before the first renders)", file.string(), f, first, end - 1));
        const ParticleFileInfo info = inspectParticleFile(file);
        if (firstInfo && info.count != firstInfo->count)
            throw InputError(fmt::format("{}: {} particles, but {} holds {}: a {{frame}} sequence pairs particles by index, "
                                         "so every frame must hold the same count", file.string(), info.count,
                                         firstFile.string(), firstInfo->count));
        if (!firstInfo) {
            firstInfo = info;
            firstFile = file;
        }
        files.push_back(file);
    }
    return files;
}

Particles ParticleSource::frame(std::uint32_t frame) const {
    if (fixed_) return *fixed_;
    Particles p;
    if (particles_.file.empty()) {
        p = generateDisk(particles_, frame, blackbody_.get());
    } else {
        const std::string path = expandPattern(particles_.file, "", frame);
        p = readParticles(path);
        // Velocity from consecutive frames (forward difference, else backward).
        if (particles_.file.find("{frame}") != std::string::npos) {
            const float dt = particles_.time_step > 0.0 ? float(particles_.time_step) : 1.0f;
            auto neighbour = [&](std::uint32_t f) -> std::optional<Particles> {
                const std::string q = expandPattern(particles_.file, "", f);
                if (!std::filesystem::exists(q)) return std::nullopt;
                Particles n = readParticles(q);
                if (n.size() != p.size())
                    throw InputError(fmt::format("{}: {} particles, but {} holds {}: a {{frame}} sequence pairs particles "
                                                 "by index, so every frame must hold the same count", q, n.size(), path,
                                                 p.size()));
                return n;
            };
            if (auto next = neighbour(frame + 1)) {
                for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = (next->position[i] - p.position[i]) / dt;
            } else if (frame > 0) {
                if (auto prev = neighbour(frame - 1))
                    for (std::size_t i = 0; i < p.size(); ++i) p.velocity[i] = (p.position[i] - prev->position[i]) / dt;
            }
        }
    }
    std::fill(p.albedo.begin(), p.albedo.end(), albedo_);
    return p;
}

}  // namespace accretion
