#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace accretion {

/// An 8-bit RGB PNG (interleaved sRGB bytes, row by row), written atomically
/// through libpng; `description`, when given, is its Description text (what
/// OpenImageIO reads as ImageDescription).
void writePng(const std::filesystem::path& file, const std::vector<std::uint8_t>& rgb, std::uint32_t width,
              std::uint32_t height, const std::string& description = {});

}  // namespace accretion
