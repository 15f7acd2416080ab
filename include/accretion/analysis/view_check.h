#pragma once
#include <map>
#include <string>
#include <vector>

#include "accretion/scene/settings.h"

namespace accretion {

/// Whether two renders show the same view: what their metadata (EXR
/// attributes, or a GPU frame's metadata under the same accretion: names)
/// say differently, and what could not be checked because one side does not
/// record it. A check that cannot be performed is said out loud: a warning,
/// an error under --strict.
struct ViewCheck {
    std::vector<std::string> differences;  ///< "frame: 3 here, 4 in the reference", ...
    std::vector<std::string> unchecked;    ///< "frame", "camera (worldToNDC)", ...
};

/// all: frame, scene, camera (worldToCamera and worldToNDC: the pose and
/// the projection, fov included), jitter, and the scene-defining settings
/// sections (particles, camera, geometry, shading); frameAndSettings: the
/// frame and those sections (a render about to be made, whose camera its
/// [camera] settings give).
enum class ViewKeys { all, frameAndSettings };

/// How a difference names the two sides: "3 here, 0 in the reference".
struct ViewSides {
    std::string image = "here";
    std::string reference = "in the reference";
};

ViewCheck checkView(const std::map<std::string, std::string>& image, const std::map<std::string, std::string>& reference,
                    ViewKeys keys = ViewKeys::all, const ViewSides& sides = {});

/// What a file checked against the scene is to the command that reads it.
enum class FileRole { reference, gpuFrame };

/// `file` (its metadata `attributes`; a reference or a GPU frame, as `role`
/// says) must be a render of frame `frame` of `scene`: the frame and the
/// scene-defining settings, a difference an error naming the file, its role
/// and the setting by key; what it does not record a warning, an error when
/// `strict`.
void requireSceneView(const std::map<std::string, std::string>& attributes, const std::string& file, FileRole role,
                      const Settings& scene, std::uint32_t frame, bool strict);

/// The scene-defining sections of a settings TOML (what two renders of the
/// same view share whatever their estimators): particles, camera, geometry, shading.
std::vector<std::string> sceneLines(const std::string& toml);

/// Reports a ViewCheck of `image` against `reference` on stderr as
/// warnings, or throws InputError (the first difference, or the unchecked
/// list) when `strict`; differences are always errors when `differencesFatal`.
void reportViewCheck(const ViewCheck& check, const std::string& image, const std::string& reference, bool strict,
                     bool differencesFatal = false);

}  // namespace accretion
