#include "accretion/core/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <csignal>
#include <fcntl.h>
#include <regex>
#include <unistd.h>

#include <fmt/format.h>

#include "accretion/core/error.h"
#include "accretion/core/output_guard.h"
#include "accretion/core/parse.h"

namespace accretion {
namespace {

std::filesystem::path tempPathFor(const std::filesystem::path& file) {
    const auto dir = file.parent_path();
    // Within the system's limit on a name, however long the output's.
    const std::string name = fmt::format(".{}.tmp{}{}", file.stem().string().substr(0, 160), ::getpid(),
                                         file.extension().string().substr(0, 40));
    return dir.empty() ? std::filesystem::path(name) : dir / name;
}

void ensureParent(const std::filesystem::path& file) {
    const auto dir = file.parent_path();
    if (dir.empty()) return;
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw InputError(fmt::format("{}: cannot create output directory: {}", displayPath(dir), ec.message()));
}

void syncFile(const std::filesystem::path& p) {
    const int fd = ::open(p.c_str(), O_RDONLY);
    if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
    }
}

}  // namespace

void writeAtomicWith(const std::filesystem::path& file, const std::function<void(const std::filesystem::path&)>& write) {
    checkOutputPath(file, "output");  // never onto a device, a directory, a FIFO
    ensureParent(file);
    const auto tmp = tempPathFor(file);
    try {
        write(tmp);
        syncFile(tmp);
        std::error_code ec;
        std::filesystem::rename(tmp, file, ec);
        if (ec) throw InputError(fmt::format("{}: cannot rename output into place: {}", displayPath(file), ec.message()));
    } catch (...) {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);
        throw;
    }
}

void writeFileAtomic(const std::filesystem::path& file, std::string_view bytes) {
    writeAtomicWith(file, [&](const std::filesystem::path& tmp) {
        std::FILE* f = std::fopen(tmp.c_str(), "wb");
        if (!f) throw InputError(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
        const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
        const int err = errno;
        const bool closed = std::fclose(f) == 0;
        if (!ok || !closed)
            throw InputError(fmt::format("{}: write failed: {}", file.string(), std::strerror(ok ? errno : err)));
    });
}

std::size_t removeStaleTemporaries(const std::filesystem::path& dir) {
    static const std::regex temporary(R"(^\..+\.tmp([0-9]+)(\.[^.]*)?$)");
    std::error_code ec;
    std::size_t removed = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.empty() ? "." : dir, ec)) {
        const std::string name = entry.path().filename().string();
        std::smatch m;
        if (!std::regex_match(name, m, temporary)) continue;
        const std::optional<std::uint64_t> id = parseUnsigned(m[1].str(), 0x7fffffff);  // a pid_t, else not ours
        if (!id) continue;
        const long pid = long(*id);
        if (pid > 0 && pid != ::getpid() && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
            removed += std::filesystem::remove(entry.path(), ec) ? 1 : 0;
    }
    return removed;
}

}  // namespace accretion
