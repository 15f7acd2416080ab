#pragma once
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "accretion/core/math.h"

namespace accretion {

/// docs/MODEL.md section 5, averaged over pixels and RGB channels:
/// relMSE = (x - ref)^2 / (ref^2 + eps), MSE = (x - ref)^2,
/// MAPE = |x - ref| / (|ref| + eps), eps = 1e-2.
struct ErrorMetrics {
    double relMSE = 0.0;
    double MSE = 0.0;
    double MAPE = 0.0;
    /// Mean of sigma_ref^2 / (ref^2 + eps): what the reference's own noise
    /// adds to relMSE in expectation (0 without a stderr layer).
    double relMSEFloor = 0.0;
    std::size_t pixels = 0;      ///< pixels measured
    /// Pixels (of those measured) the reference lights: not 0 in every
    /// channel. The black background agrees trivially, so agreement is
    /// counted over these alone:
    std::size_t lit = 0;
    /// lit pixels equal to the reference in all three channels, and within
    /// the relative tolerance of computeErrors in each (|x - ref| <= tol
    /// |ref|): agreement of two renderers of one quantity.
    std::size_t identical = 0, withinTolerance = 0;
    /// Pixels left out because a value of the image, the reference or its
    /// stderr is NaN or infinite, and the first few of them (row-major indices).
    std::size_t nonFinite = 0;
    std::vector<std::size_t> firstNonFinite;  ///< at most kNonFiniteListed
    static constexpr std::size_t kNonFiniteListed = 5;
};

/// A mean over pixels is NaN with one NaN pixel: InputError "FILE: LAYER is
/// not finite at pixel (x, y)" naming the first (`width`: the image's).
void requireFinitePixels(const std::vector<Vec3>& pixels, const std::string& file, const char* layer, std::uint32_t width);

inline constexpr double kRelMseEpsilon = 1e-2;
inline constexpr double kAgreementTolerance = 1e-4;

ErrorMetrics computeErrors(const std::vector<Vec3>& x, const std::vector<Vec3>& ref,
                           const std::vector<Vec3>* refStderr = nullptr, double eps = kRelMseEpsilon,
                           double tolerance = kAgreementTolerance);

/// Flicker: the relMSE of an estimate's frame-to-frame change against the
/// reference sequence's own change, mean over pixels and channels of
/// ((x - xPrev) - (ref - refPrev))^2 / (ref^2 + eps). With independent noise
/// in each frame it is the two frames' relMSE summed; temporal reuse, whose
/// errors persist, flickers less than its error. `change` (optional) gets
/// the reference's own change, ((ref - refPrev))^2 / (ref^2 + eps).
double flickerRelMse(const std::vector<Vec3>& x, const std::vector<Vec3>& xPrev, const std::vector<Vec3>& ref,
                     const std::vector<Vec3>& refPrev, double* change = nullptr, double eps = kRelMseEpsilon);

/// An RGB layer of an EXR file, read with OpenEXR (half, float or uint
/// channels, as floats): the pixels of its data window, which may be any
/// part of (or reach outside) the display window of the whole image.
struct RgbLayer {
    std::uint32_t width = 0, height = 0;          ///< the display window (the whole image)
    int x0 = 0, y0 = 0;                           ///< the data window's upper-left pixel
    std::uint32_t dataWidth = 0, dataHeight = 0;  ///< and its size
    std::vector<Vec3> rgb;                        ///< the data window's pixels, row by row
    /// The data window is the display window.
    bool whole() const { return x0 == 0 && y0 == 0 && dataWidth == width && dataHeight == height; }
    /// The pixels of window [x0, x0 + w) x [y0, y0 + h), which the data window must contain.
    std::vector<Vec3> window(int x, int y, std::uint32_t w, std::uint32_t h) const;
};

/// Read layer `layer` ("" = R,G,B; "Lr" = Lr.R, Lr.G, Lr.B; ...; a channel
/// of its own such as "spp" or "depth.Z" in all three components). Throws
/// InputError naming the file when it is not an OpenEXR file (by its magic:
/// a PNG or JPEG is display-referred and 8-bit, not a measurement), cannot
/// be read or lacks the channels.
RgbLayer readExrLayer(const std::filesystem::path& file, const std::string& layer);
/// The same with the three channels named (a GPU frame's own names).
RgbLayer readExrChannels(const std::filesystem::path& file, const std::vector<std::string>& channels);
/// An EXR's attributes as text (strings as they are, numbers and matrices
/// printed), by name: what compare checks between two images.
std::map<std::string, std::string> readExrAttributes(const std::filesystem::path& file);
/// A 32-bit unsigned channel (e.g. particle.id) over the data window, read
/// as integers; empty when the file has no such channel.
std::vector<std::uint32_t> readExrUintChannel(const std::filesystem::path& file, const std::string& name);
/// True if the file has all three channels of the layer.
bool exrHasLayer(const std::filesystem::path& file, const std::string& layer);

}  // namespace accretion
