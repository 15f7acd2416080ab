#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <sys/types.h>

namespace accretion {

/// A path for messages: one longer than 120 characters is cut in the middle.
std::string displayPath(const std::filesystem::path& file);

/// Refuse a path no output may take (InputError naming `what`, e.g. the
/// flag): an existing file that is not a regular file (a device node, a
/// directory, a FIFO, a socket, also through a symbolic link), or one the
/// system cannot hold (a name over 255 bytes, a path over 4095).
void checkOutputPath(const std::filesystem::path& file, std::string_view what);

/// The files a command reads, so that none of its outputs lands on one of
/// them: checked before anything is written, by identity (device and inode,
/// so a hard link, a symbolic link or another spelling of an input is found).
class OutputGuard {
public:
    /// An input of the run; a path that does not exist is ignored.
    void addInput(const std::filesystem::path& file);

    /// checkOutputPath, and refuse `file` when it is one of the inputs.
    void check(const std::filesystem::path& file, std::string_view what) const;

private:
    struct Input {
        dev_t device;
        ino_t inode;
        std::string name;
    };
    std::vector<Input> inputs_;
};

/// An exclusive lock on a run's outputs: flock(2) on `file` (NAME.lock),
/// which holds the owner's PID. A second run asking for the same lock is
/// refused with an InputError naming that PID. Released, and the file
/// removed, when destroyed; a run killed with -9 releases it too (the
/// kernel drops the lock, the next run takes the file over).
class OutputLock {
public:
    explicit OutputLock(std::filesystem::path file);
    ~OutputLock();
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;

private:
    std::filesystem::path file_;
    int fd_ = -1;
};

}  // namespace accretion
