#pragma once
#include <string_view>

namespace accretion {
/// Project version and git commit, recorded in every output.
std::string_view version();
}  // namespace accretion
