#!/usr/bin/env bash
# The whole test suite, as CI runs it (the README's second command, after
# scripts/setup.sh), stage by stage:
#   1. the Release build of everything, and its Catch2 tests (ctest);
#   2. the OptiX twin's compile without a GPU (scripts/compile_twin.sh),
#      and the one-node Slurm cluster's job-array and requeue test
#      (scripts/slurm/cluster_test.sh), which starts beside stage 1's ctest:
#      alone it takes 43-45 s and about 60 s of CPU, and its waits on
#      daemons and sleeps left a core idle in a stage of its own;
#   3. the suite again under AddressSanitizer and UBSan (scripts/sanitize.sh;
#      the command-line tests from stage 1's harness, run against the
#      instrumented program);
#   4. libFuzzer on every input reader (scripts/fuzz.sh, SECONDS per target).
# Each stage's wall time goes to stderr; the first failure stops the run.
#   scripts/test.sh [SECONDS]      (default 4)
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds=${1:-4}
start=$SECONDS

stage() {
    local name=$1 t0=$SECONDS
    shift
    "$@"
    echo "test.sh: $name: $((SECONDS - t0)) s" >&2
}

# The Slurm test runs in the background from the Release build's ctest on
# (it needs the build's binary); its output is held back and printed, whole,
# after the twin's compile.
slurm_log=$(mktemp)
slurm_pid=
trap 'rm -f "$slurm_log"; [ -z "$slurm_pid" ] || kill "$slurm_pid" 2>/dev/null || true' EXIT
twin_and_cluster() {
    local twin=0 cluster=0
    bash scripts/compile_twin.sh || twin=$?
    wait "$slurm_pid" || cluster=$?
    slurm_pid=
    cat "$slurm_log"
    ((cluster == 0)) || { echo "test.sh: the Slurm test failed (exit $cluster)" >&2; return 1; }
    ((twin == 0)) || { echo "test.sh: the twin's compile failed (exit $twin)" >&2; return 1; }
}

stage "Release build" bash -c 'cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null && cmake --build build'
bash scripts/slurm/cluster_test.sh >"$slurm_log" 2>&1 &
slurm_pid=$!
stage "ctest (the Slurm test beside it)" ctest --test-dir build --output-on-failure -j2
stage "twin compile, and the Slurm test's end" twin_and_cluster
stage "sanitizers" bash scripts/sanitize.sh
stage "fuzzing" bash scripts/fuzz.sh "$fuzz_seconds"
echo "test.sh: all stages passed in $((SECONDS - start)) s" >&2
