#!/usr/bin/env bash
# The whole performance suite in one command (Release build, both cores):
# bars against bare Embree loops, scaling curves, memory, micro-benchmarks.
# Writes bench/results.json, bench/scaling_*.csv/.png and prints the table.
#   bench/run.sh [--quick]      (--quick: no tree 1% reference, no 1M frame; ~1 min)
# The full run takes about 8 minutes on the project's 2-core machine.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build >/dev/null
exec ./build/bench/accretion_suite --out bench --accretion build/accretion --micro build/bench/accretion_bench "$@"
