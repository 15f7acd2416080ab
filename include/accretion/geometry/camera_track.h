#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "accretion/geometry/camera.h"
#include "accretion/scene/settings.h"

namespace accretion {

/// How a camera file states its matrices (docs/MODEL.md section 3, cameras):
/// - storage: the 16 numbers of a matrix are its rows (row_major) or its
///   columns (column_major);
/// - vectors: the matrix multiplies column vectors (M v: OpenGL, GLM,
///   Vulkan) or row vectors (v M: DirectXMath);
/// - handedness: view space looks down -z (right) or +z (left);
/// - clip: NDC y up (opengl, d3d) or down (vulkan).
struct CameraConvention {
    enum class Storage { row_major, column_major } storage = Storage::column_major;
    enum class Vectors { column, row } vectors = Vectors::column;
    enum class Handedness { right, left } handedness = Handedness::right;
    enum class Clip { opengl, d3d, vulkan } clip = Clip::opengl;

    /// The presets: "opengl" (column_major, column, right, opengl), "vulkan"
    /// (the same, clip vulkan), "d3d" (row_major, row, left, d3d).
    static bool preset(const std::string& name, CameraConvention& out);
};

/// A 4x4 matrix as it acts on column vectors: m[row][col].
using Mat4 = std::array<std::array<double, 4>, 4>;

/// A frame's pose from the engine's view (world to view) and projection
/// matrices in the given convention, for an image of width x height. The
/// screen's axes are taken from the view matrix as they are (so the image is
/// the engine's whatever the handedness of its world); the projection gives
/// the field of view, and its off-centre terms the jitter. Throws InputError
/// (`where` names the file and frame) for a view that is not rigid, a
/// projection that is not a perspective one, or an aspect ratio unlike the
/// image's.
CameraPose poseFromMatrices(const Mat4& view, const Mat4& projection, const CameraConvention& convention,
                            std::uint32_t width, std::uint32_t height, const std::string& where);

/// The view and projection matrices of a pose in a convention (the inverse
/// of poseFromMatrices, exact for what it reads back: the field of view is
/// chosen so that its reciprocal round-trips).
void matricesFromPose(const CameraPose& pose, const CameraConvention& convention, std::uint32_t width,
                      std::uint32_t height, Mat4& view, Mat4& projection);

/// The camera of every frame: the scene's path, or the engine's cameras of
/// camera.file, read once. The file is JSON:
///   { "convention": "opengl" | "d3d" | "vulkan" | {storage, vectors, handedness, clip},
///     "jitter_units": "pixels" | "ndc",
///     "frames": [ { "frame": 0, "eye": [..], "look_at": [..], "up": [..], "fov": 45, "jitter": [jx, jy] },
///                 { "frame": 1, "view": [16], "projection": [16] }, ... ] }
/// or CSV with a header naming its columns: frame, then eye_x..z, look_at_x..z,
/// up_x..z, fov (degrees), or view_0..view_15 and projection_0..projection_15;
/// optionally jitter_x, jitter_y; the convention in a first line
/// `# convention = d3d`. Errors name the file and the record (InputError).
class CameraTrack {
public:
    explicit CameraTrack(const CameraSettings& settings);

    /// The pose of a frame; a frame the file does not hold is an InputError.
    CameraPose pose(std::uint32_t frame) const;
    /// The camera of a frame.
    Camera at(std::uint32_t frame) const { return Camera::fromPose(pose(frame), settings_.width, settings_.height); }
    /// The frames of [first, end) the file lacks (none for a path).
    std::vector<std::uint32_t> missing(std::uint32_t first, std::uint32_t end) const;
    bool fromFile() const { return !settings_.file.empty(); }

private:
    CameraSettings settings_;
    std::map<std::uint32_t, CameraPose> poses_;
};

/// Write the cameras of frames [first, end) of a track as a camera file
/// (JSON; matrices in `convention`, or look-at poses when `matrices` is
/// false) that CameraTrack reads back to the same poses.
void writeCameraFile(const std::filesystem::path& file, const CameraTrack& track, const CameraSettings& settings,
                     std::uint32_t first, std::uint32_t end, const CameraConvention& convention, bool matrices);

}  // namespace accretion
