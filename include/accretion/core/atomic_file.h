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

/// Remove the temporary files that writers killed mid-write (kill -9, power
/// loss) left in `dir`: ".<name>.tmp<pid>.<ext>" whose process is gone.
/// Returns how many were removed.
std::size_t removeStaleTemporaries(const std::filesystem::path& dir);

}  // namespace accretion
