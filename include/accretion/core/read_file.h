#pragma once
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace accretion {

/// The one way an input file is opened: InputError "FILE: cannot open WHAT"
/// when it is missing or unreadable, "FILE: is a directory, not WHAT" for a
/// directory (e.g. what = "scene file").
std::ifstream openInputFile(const std::filesystem::path& file, std::string_view what);

/// A whole file's bytes (openInputFile, then "FILE: cannot read WHAT").
std::string readWholeFile(const std::filesystem::path& file, std::string_view what);

/// Bytes of an open input file from the current position to its end (the
/// check a header's sizes are held to before anything is allocated on them).
std::uint64_t bytesLeft(std::ifstream& in);

/// `text` without a leading UTF-8 byte-order mark (as Windows tools and
/// Nsight's CSV export write it).
std::string_view withoutBom(std::string_view text);

}  // namespace accretion
