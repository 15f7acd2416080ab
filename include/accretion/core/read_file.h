#pragma once
#include <filesystem>
#include <string>
#include <string_view>

namespace accretion {

/// A whole file's bytes. InputError "FILE: cannot open WHAT" or "FILE: cannot
/// read WHAT" (e.g. what = "scene file").
std::string readWholeFile(const std::filesystem::path& file, std::string_view what);

}  // namespace accretion
