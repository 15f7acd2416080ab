#pragma once
#include <filesystem>
#include <functional>
#include <string_view>

namespace accretion {

/// Write `bytes` to `file` through a temporary file in the same directory
/// and an atomic rename: readers see the old file or the new one, never a
/// partial one. Creates missing parent directories. Throws InputError.
void writeFileAtomic(const std::filesystem::path& file, std::string_view bytes);

/// Same, for writers that need a path (image libraries): `write(tmpPath)`
/// produces the temporary file, which is then renamed into place. The
/// temporary keeps the extension of `file`.
void writeAtomicWith(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write);

}  // namespace accretion
