#pragma once
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "accretion/io/provenance.h"
#include "accretion/render/frame_renderer.h"

namespace accretion {

/// OpenEXR's standard camera attributes of a frame, as Imath stores them
/// (row vectors: p' = p M, 16 floats row by row). worldToCamera maps into a
/// space with x right, y up and z the view direction (left-handed, as
/// OpenEXR defines it, whatever the world's handedness); worldToNDC maps onto
/// the display window, (0, 0) its upper-left and (1, 1) its lower-right
/// corner after the division by w, so that the frame's (jittered) sample of
/// pixel (x, y) lands at ((x + 0.5) / width, (y + 0.5) / height).
struct ExrCameraMatrices {
    std::array<float, 16> worldToCamera{}, worldToNDC{};
};
ExrCameraMatrices exrCameraMatrices(const CameraPose& camera, std::uint32_t width, std::uint32_t height);

/// Write a frame as a multi-layer float32 EXR (zip): R,G,B, Le.*, Lr.*,
/// depth.Z, N.X/Y/Z, particle.id (uint32, 0xffffffff on a miss), rejected
/// (non-finite samples rejected, render.nonfinite), and when
/// `withErrors` Lr_stderr.* and spp. Atomic: temp file + rename.
void writeFrameExr(const std::filesystem::path& file, const FrameImage& image, bool withErrors,
                   const OutputMetadata& metadata);

/// A float EXR of named channels (e.g. bias maps), written atomically.
struct FloatChannel {
    std::string name;
    std::vector<float> values;  ///< width x height, row-major
};
/// Where a window's pixels lie in the whole image (the EXR's data window
/// inside its display window); fullWidth 0: the pixels are the whole image.
struct DataWindow {
    int x = 0, y = 0;
    std::uint32_t fullWidth = 0, fullHeight = 0;
};
void writeChannelsExr(const std::filesystem::path& file, std::uint32_t width, std::uint32_t height,
                      const std::vector<FloatChannel>& channels, const OutputMetadata& metadata, DataWindow window = {});

/// A counter heatmap as an 8-bit PNG in false colour (io/false_colour.h): 0
/// dark purple, the 99.5th percentile of the non-zero values (or the
/// maximum) bright yellow, with a colour bar, its scale and `title` (the
/// counter and its unit) under the image. Atomic.
void writeHeatmapPng(const std::filesystem::path& file, const std::vector<float>& values, std::uint32_t width,
                     std::uint32_t height, const std::string& title);

/// An EXR's pixels in their native 4-byte channel formats, with its header:
/// what `merge` reads from a shard and writes back with new lighting.
struct RawExr {
    std::uint32_t width = 0, height = 0;
    std::vector<std::string> channels;  ///< names, in file order
    std::vector<std::uint32_t> bits;     ///< interleaved, width x height x channels
    std::vector<bool> uints;             ///< per channel: UINT (else FLOAT)
    std::map<std::string, std::string> attributes;  ///< string attributes (accretion:*)
    /// Float attributes as they were (the camera's worldToCamera, worldToNDC,
    /// accretion:jitter): name -> (OpenEXR type name, values).
    std::map<std::string, std::pair<std::string, std::vector<float>>> floatAttributes;
    std::string file;                    ///< where it was read (for messages)

    /// Index of a channel; throws InputError naming the file when absent.
    std::size_t channel(const std::string& name) const;
    float value(std::size_t px, std::size_t c) const;
    void set(std::size_t px, std::size_t c, float v);
};
RawExr readRawExr(const std::filesystem::path& file);
void writeRawExr(const std::filesystem::path& file, const RawExr& exr);

/// An 8-bit RGB PNG (interleaved sRGB bytes), written atomically.
void writeRgb8Png(const std::filesystem::path& file, const std::vector<std::uint8_t>& px, std::uint32_t width,
                  std::uint32_t height);

}  // namespace accretion
