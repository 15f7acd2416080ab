#pragma once
#include <cstdint>
#include <filesystem>
#include <vector>
#include <memory>
#include <optional>

#include "accretion/particles/blackbody.h"
#include "accretion/particles/particles.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// Where a frame's particles come from: the disk generator, per-frame files
/// (velocity from consecutive frames), or a fixed in-memory set (tests).
class ParticleSource {
public:
    /// From the scene: particles.file if set, else the generator.
    explicit ParticleSource(const Settings& settings);
    /// A fixed particle set, the same every frame (albedo/type as given).
    static ParticleSource fixed(Particles particles);

    /// The particles of a frame, albedo filled from the scene.
    Particles frame(std::uint32_t frame) const;
    /// True if every frame holds the same particles.
    bool isStatic() const;

    /// Before a run of frames [first, end): every particle file it reads
    /// (the frames' and the neighbours that give velocities) inspected
    /// (exists, header, size) and, for a {frame} sequence, all with the
    /// same count, so that particle i is the same particle in every frame.
    /// InputError names the first file that differs. Returns the files.
    std::vector<std::filesystem::path> checkFiles(std::uint32_t first, std::uint32_t end) const;

private:
    ParticleSource() = default;
    ParticleSettings particles_;
    Vec3 albedo_{0.8f};
    std::optional<Particles> fixed_;
    std::shared_ptr<const BlackbodyTable> blackbody_;  ///< generator: built once per source
};

}  // namespace accretion
