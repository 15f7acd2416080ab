#include "accretion/core/stop_signal.h"

#include <csignal>

namespace accretion {
namespace {

// A signal handler can only talk through a static of this type.
volatile std::sig_atomic_t received = 0;

extern "C" void onStopSignal(int signal) {
    if (received == signal) {  // asked twice: stop now
        std::signal(signal, SIG_DFL);
        std::raise(signal);
    }
    received = signal;
}

struct sigaction previousInt, previousTerm;

}  // namespace

StopSignal::StopSignal() {
    received = 0;
    struct sigaction sa = {};
    sa.sa_handler = onStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &previousInt);
    sigaction(SIGTERM, &sa, &previousTerm);
}

StopSignal::~StopSignal() {
    sigaction(SIGINT, &previousInt, nullptr);
    sigaction(SIGTERM, &previousTerm, nullptr);
}

int StopSignal::pending() const { return received; }

const char* StopSignal::name(int signal) {
    switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "a signal";
    }
}

}  // namespace accretion
