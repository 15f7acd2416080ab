#include "accretion/core/output_guard.h"

#include <cerrno>
#include <climits>
#include <cstring>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include "accretion/core/error.h"

namespace accretion {

std::string displayPath(const std::filesystem::path& file) {
    const std::string s = file.string();
    if (s.size() <= 120) return s;
    return fmt::format("{}...{} ({} characters)", s.substr(0, 60), s.substr(s.size() - 40), s.size());
}

void checkOutputPath(const std::filesystem::path& file, std::string_view what) {
    const std::string s = file.string();
    if (s.empty()) throw InputError(fmt::format("{}: empty output path", what));
    if (s.size() >= PATH_MAX)
        throw InputError(fmt::format("{} {}: the path is longer than the system's limit of {} bytes", what,
                                     displayPath(file), PATH_MAX - 1));
    for (const auto& part : file)
        if (part.string().size() > NAME_MAX)
            throw InputError(fmt::format("{} {}: a name of {} bytes in the path, over the system's limit of {}", what,
                                         displayPath(file), part.string().size(), NAME_MAX));
    struct stat st;
    if (::stat(file.c_str(), &st) != 0) return;  // a new path (or one that cannot be reached: the write says why)
    if (!S_ISREG(st.st_mode)) {
        const char* kind = S_ISDIR(st.st_mode) ? "a directory" : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                         : S_ISFIFO(st.st_mode) ? "a FIFO" : S_ISSOCK(st.st_mode) ? "a socket" : "not a regular file";
        throw InputError(fmt::format("{} {}: is {}; outputs go to regular files or new paths", what, displayPath(file), kind));
    }
}

void OutputGuard::addInput(const std::filesystem::path& file) {
    struct stat st;
    if (::stat(file.c_str(), &st) == 0) inputs_.push_back({st.st_dev, st.st_ino, file.string()});
}

void OutputGuard::check(const std::filesystem::path& file, std::string_view what) const {
    checkOutputPath(file, what);
    struct stat st;
    if (::stat(file.c_str(), &st) != 0) return;
    for (const Input& in : inputs_)
        if (in.device == st.st_dev && in.inode == st.st_ino)
            throw InputError(fmt::format("{} {}: {}; writing it would destroy it", what, displayPath(file),
                                         in.name == file.string() ? std::string("an input of this run")
                                                                  : "the same file as the input " + displayPath(in.name)));
}

OutputLock::OutputLock(std::filesystem::path file) : file_(std::move(file)) {
    checkOutputPath(file_, "lock");
    if (!file_.parent_path().empty()) {
        std::error_code ec;
        std::filesystem::create_directories(file_.parent_path(), ec);
        if (ec)
            throw InputError(fmt::format("{}: cannot create output directory: {}", displayPath(file_.parent_path()), ec.message()));
    }
    for (int attempt = 0; attempt < 100; ++attempt) {
        const int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0) throw InputError(fmt::format("{}: cannot create the lock of this run's outputs: {}", displayPath(file_), std::strerror(errno)));
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int err = errno;
            char buf[32] = {};
            const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
            ::close(fd);
            if (err != EWOULDBLOCK) throw InputError(fmt::format("{}: cannot lock: {}", displayPath(file_), std::strerror(err)));
            const std::string pid = n > 0 ? std::string(buf, std::size_t(n)) : std::string("?");
            throw InputError(fmt::format("{}: another run (PID {}) is writing these outputs; wait for it to finish or stop it",
                                         displayPath(file_), pid.substr(0, pid.find_first_of("\n "))));
        }
        // Locked: but a finishing owner may have removed the file after we
        // opened it; the lock must be on the file the path names now.
        struct stat held, named;
        if (::fstat(fd, &held) == 0 && ::stat(file_.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
            held.st_ino == named.st_ino) {
            const std::string pid = fmt::format("{}\n", ::getpid());
            if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != ssize_t(pid.size())) {
                ::close(fd);
                throw InputError(fmt::format("{}: cannot write the lock: {}", displayPath(file_), std::strerror(errno)));
            }
            fd_ = fd;
            return;
        }
        ::close(fd);
    }
    throw InputError(fmt::format("{}: cannot take the lock (it keeps being replaced)", displayPath(file_)));
}

OutputLock::~OutputLock() {
    if (fd_ < 0) return;
    ::unlink(file_.c_str());  // while still holding it: a waiting run then retries on a new file
    ::close(fd_);
}

}  // namespace accretion
