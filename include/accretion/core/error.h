#pragma once
#include <stdexcept>
#include <string>

#include <fmt/format.h>

namespace accretion {

/// The user's error: bad scene, particle file or command line. The message
/// names where (file:line, file record N, or the command-line flag).
class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A broken internal invariant: a bug in accretion, never the user's fault.
class InternalError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

[[noreturn]] void failCheck(const char* expr, const char* file, int line);

}  // namespace accretion

/// Cheap invariant check, always on.
#define ACC_CHECK(expr) \
    do { if (!(expr)) ::accretion::failCheck(#expr, __FILE__, __LINE__); } while (0)
