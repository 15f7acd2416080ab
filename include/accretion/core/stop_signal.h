#pragma once

namespace accretion {

/// While alive, SIGINT and SIGTERM do not kill the process: they are
/// recorded, and long work polls pending() at safe points (between chunks)
/// to checkpoint and exit. A second signal of the same kind kills at once.
/// The previous handlers come back on destruction.
class StopSignal {
public:
    StopSignal();
    ~StopSignal();
    StopSignal(const StopSignal&) = delete;
    StopSignal& operator=(const StopSignal&) = delete;

    /// The signal number received, 0 if none.
    int pending() const;
    static const char* name(int signal);
};

/// Thrown at a safe point after a stop request was honoured (checkpoint written).
struct Interrupted {
    int signal;
};

}  // namespace accretion
