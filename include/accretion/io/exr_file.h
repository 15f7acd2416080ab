#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace accretion {

/// OpenEXR files as accretion writes and reads them, through OpenEXR itself
/// (one scanline part, zip). The renderer links OpenEXR and libpng rather
/// than OpenImageIO: Debian's OpenImageIO loads about 250 shared libraries
/// (ffmpeg, OpenCV, GDAL...), 0.2 s at every start of a process, where
/// accretion starts in a few milliseconds without them. The tests read the
/// files back with OpenImageIO, independently of this code.

enum class ExrChannelType : std::uint8_t { uint32, half, float32 };

/// What a file's header says: windows, channels and attributes.
struct ExrHeader {
    std::uint32_t fullWidth = 0, fullHeight = 0;  ///< the display window (its origin taken as 0, 0)
    int x0 = 0, y0 = 0;                            ///< the data window's origin in the display window
    std::uint32_t width = 0, height = 0;          ///< the data window's size
    std::vector<std::string> channels;             ///< names, in the file's (sorted) order
    std::vector<ExrChannelType> types;
    std::map<std::string, std::string> strings;   ///< string attributes
    /// Float attributes (m44f, v2f, float...): name -> (OpenEXR type name, values).
    std::map<std::string, std::pair<std::string, std::vector<float>>> floats;
    /// Every attribute as text (strings as they are, numbers space-separated).
    std::map<std::string, std::string> printed;

    /// Index of a channel, or -1.
    int channelIndex(const std::string& name) const;
};

/// An EXR file opened once: its header, then the pixels of its channels.
class ExrReader {
public:
    /// Throws InputError naming the file when it is not a readable EXR.
    explicit ExrReader(const std::filesystem::path& file);
    ~ExrReader();
    ExrReader(const ExrReader&) = delete;
    ExrReader& operator=(const ExrReader&) = delete;

    const ExrHeader& header() const { return header_; }

    /// The data window's pixels of the named channels, interleaved, each as
    /// the bits of a 4-byte value: `asFloat` converts every channel to float
    /// (a half or uint channel by value); otherwise each keeps its own type
    /// (uint or float bits; a half channel is refused).
    std::vector<std::uint32_t> pixels(const std::vector<std::string>& channels, bool asFloat);

private:
    struct File;
    std::filesystem::path path_;
    std::unique_ptr<File> file_;
    ExrHeader header_;
};

/// The header alone.
ExrHeader readExrHeader(const std::filesystem::path& file);

/// A file to write: 4-byte channels, interleaved pixels of the data window.
struct ExrImage {
    std::uint32_t fullWidth = 0, fullHeight = 0;
    int x0 = 0, y0 = 0;
    std::uint32_t width = 0, height = 0;
    std::vector<std::string> channels;
    std::vector<bool> uints;                      ///< per channel: uint32 (else float)
    const std::uint32_t* bits = nullptr;          ///< width x height x channels
    std::map<std::string, std::string> strings;
    std::map<std::string, std::pair<std::string, std::vector<float>>> floats;
};

/// Writes `image` atomically (a temporary beside it, then a rename).
void writeExr(const std::filesystem::path& file, const ExrImage& image);

}  // namespace accretion
