#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer,
# in its own build directory (build-asan). Any finding fails the run: ASan's
# report, UBSan's trap (or its report, with ACCRETION_UBSAN_REPORTS=1).
set -euo pipefail
cd "$(dirname "$0")/.."
# UBSan traps (an illegal instruction: the test fails, named by ctest) rather
# than calling its runtime to print a report: the build takes about a fifth
# less (particle_space.cpp 38 s against 48 under ASan). To see the report of
# a trap, ACCRETION_UBSAN_REPORTS=1 builds the reporting form (build-asan-reports).
flags="-fsanitize=address,undefined -fno-omit-frame-pointer"
dir=build-asan
if [ "${ACCRETION_UBSAN_REPORTS:-0}" = 1 ]; then
  flags="$flags -fno-sanitize-recover=undefined"
  dir=build-asan-reports
else
  flags="$flags -fsanitize-undefined-trap-on-error"
fi
# -Og -g1: UBSan at -O2 -g compiled some files 4x slower (cmd_batch.cpp 133 s
# against 34 s) for no more checks; -g1 keeps the line tables stack traces need.
# A unity build (16 files per unit) instantiates the shared templates (fmt,
# json, CLI11, Catch2) once per unit rather than once per file: the build
# takes about 4 min instead of 10 on 2 cores. Files of one unit share their
# anonymous namespaces, so file-local types need names no other file uses.
# The command-line tests' harness (it starts the program and reads back its
# files) is the Release build's, when there is one: what they test, the
# program, is this build's (tests/CMakeLists.txt, ACCRETION_CLI_TESTS_FROM).
# That leaves their two unity batches, about a minute on 2 cores under ASan
# and UBSan, uncompiled here.
cli_tests=
if [ -f build/build.ninja ] && cmake --build build --target accretion_cli_tests >/dev/null; then
  cli_tests=$PWD/build/tests/accretion_cli_tests
fi
cmake -S . -B "$dir" -G Ninja -DACCRETION_CLI_TESTS_FROM="$cli_tests" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-Og -g1 -DNDEBUG" \
  -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 -DACCRETION_BUILD_BENCH=OFF \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$dir"
# The statistical tests over seeds run 1/8 of their seeds here (the
# estimator agreement a quarter of its samples): every code path still runs
# under the sanitizers, at the same confidence; their power is checked in
# the Release stage, which runs them whole. kill -9 at random moments: 10
# kills here, 25 there.
ACCRETION_TEST_SEED_DIVISOR=8 ACCRETION_KILL_TRIALS=10 ASAN_OPTIONS=abort_on_error=0:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir "$dir" --output-on-failure -j2
