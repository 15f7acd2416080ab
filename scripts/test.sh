#!/usr/bin/env bash
# The whole test suite, as CI runs it (the README's second command, after
# scripts/setup.sh), stage by stage:
#   1. the Release build of everything, and its Catch2 tests (ctest);
#   2. the one-node Slurm cluster's job-array and requeue test
#      (scripts/slurm/cluster_test.sh) and, beside it, the OptiX twin's
#      compile without a GPU (scripts/compile_twin.sh): the first mostly
#      waits on daemons and sleeps, the second on nvcc, so they share the
#      two cores;
#   3. the suite again under AddressSanitizer and UBSan (scripts/sanitize.sh);
#   4. libFuzzer on every input reader (scripts/fuzz.sh, SECONDS per target).
# Each stage's wall time goes to stderr; the first failure stops the run.
#   scripts/test.sh [SECONDS]      (default 6)
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-6}
start=$SECONDS

stage() {
    local name=$1 t0=$SECONDS
    shift
    "$@"
    echo "test.sh: $name: $((SECONDS - t0)) s" >&2
}

# The Slurm test's output is held back and printed after the twin's, whole.
cluster_and_twin() {
    local log
    log=$(mktemp)
    bash scripts/slurm/cluster_test.sh >"$log" 2>&1 &
    local pid=$! twin=0
    bash scripts/compile_twin.sh || twin=$?
    local cluster=0
    wait "$pid" || cluster=$?
    cat "$log"
    rm -f "$log"
    ((cluster == 0)) || { echo "test.sh: the Slurm test failed (exit $cluster)" >&2; return 1; }
    ((twin == 0)) || { echo "test.sh: the twin's compile failed (exit $twin)" >&2; return 1; }
}

stage "Release build" bash -c 'cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null && cmake --build build'
stage "ctest" ctest --test-dir build --output-on-failure -j2
stage "Slurm test and twin compile" cluster_and_twin
stage "sanitizers" bash scripts/sanitize.sh
stage "fuzzing" bash scripts/fuzz.sh "$fuzz_seconds"
echo "test.sh: all stages passed in $((SECONDS - start)) s" >&2
