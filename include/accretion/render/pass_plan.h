#pragma once
#include <string>
#include <string_view>
#include <vector>

#include "accretion/scene/settings.h"

namespace accretion {

/// One line of a frame's pass plan: a pass (or the work inside one) and
/// whether it runs, with the reason when it does not.
struct PlannedStep {
    std::string name;
    bool runs = true;
    std::string why;  ///< what it does, or why it is skipped
};

/// What a scene's frames must do, decided from the settings before
/// rendering (issue 5: a scene runs only the passes it needs).
struct PassPlan {
    bool staticGeometry = false;  ///< static particles and camera: one BVH build for all frames
    bool alphaFilter = false;     ///< disc alpha: filter (any-hit) callbacks attached
    bool lighting = true;         ///< any lighting pass at all
    bool lightSampler = false;    ///< buildLightSampler: alias table or light tree
    bool shadowRays = true;       ///< visibility by shadow rays
    bool reservoirs = false;      ///< ris / restir reservoirs
    bool history = false;         ///< restir temporal reuse: history buffers and motion kept
    bool spatial = false;         ///< restir spatial reuse
    bool upsample = false;        ///< restir at reduced resolution
    bool previousBvh = false;     ///< a second BVH kept for basic_visibility
    bool counting = false;        ///< counter code compiled into the loops
    std::vector<PlannedStep> steps;
};

/// The plan of every frame of a run with these settings.
PassPlan planPasses(const Settings& settings);

/// Particles identical in every frame (generator without motion, or one file without {frame}).
bool staticParticles(const ParticleSettings& particles);

/// "name   runs/skipped  why" lines.
std::string formatPlan(const PassPlan& plan);

}  // namespace accretion
