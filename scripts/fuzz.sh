#!/usr/bin/env bash
# libFuzzer runs of the scene parser, the particle readers, the PLY header,
# the accumulation reader and the batch jobs file (clang from
# Debian, AddressSanitizer + UBSan), seeded from tests/fuzz/corpus_*.
#   scripts/fuzz.sh [seconds per target]    (CI: 4; a longer run: 3600)
# New inputs go to build-fuzz/corpus_*; a crash leaves build-fuzz/crash-* and fails.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-30}
# -O1 with line tables (libFuzzer's usual flags): a unity batch compiles in
# about 34 s instead of 40 at -O2 -g, and a stack trace keeps its lines. Only
# the readers and what they call are compiled (accretion_fuzz_readers in
# CMakeLists.txt): the build took 25 s instead of 50 with the whole base.
CXX=clang++ CC=clang cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" -DACCRETION_FUZZ=ON \
  -DACCRETION_BUILD_TESTS=OFF -DACCRETION_BUILD_BENCH=OFF >/dev/null
targets="scene particles ply_header accumulation jobs"
cmake --build build-fuzz --target $(for t in $targets; do printf "fuzz_%s " $t; done)
# Two targets at a time (one per core), each for its full time.
jobs=${FUZZ_JOBS:-2}
pids=() names=()
for target in $targets; do
  mkdir -p build-fuzz/corpus_$target
  cp -n tests/fuzz/corpus_$target/* build-fuzz/corpus_$target/ 2>/dev/null || true
  (cd build-fuzz && ./fuzz_$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=4096 \
      -print_final_stats=1 corpus_$target > fuzz_$target.log 2>&1) &
  pids+=($!) names+=($target)
  if ((${#pids[@]} >= jobs)); then
    wait "${pids[0]}" || { tail -30 build-fuzz/fuzz_${names[0]}.log; exit 1; }
    tail -3 build-fuzz/fuzz_${names[0]}.log
    pids=("${pids[@]:1}") names=("${names[@]:1}")
  fi
done
for i in "${!pids[@]}"; do
  wait "${pids[$i]}" || { tail -30 build-fuzz/fuzz_${names[$i]}.log; exit 1; }
  tail -3 build-fuzz/fuzz_${names[$i]}.log
done
