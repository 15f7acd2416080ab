#!/usr/bin/env bash
# How long a Monte Carlo render takes to stop after SIGTERM: the wait a
# cluster's grace period must cover (docs/batches.md, "Checkpoints"). split at
# 65536 spp on disk_100k at 320x180, SIGTERM DELAY seconds after the frame
# starts, RUNS times per binary, binaries side by side (e.g. an older build
# against this one); prints each latency and the median per binary.
#   bash bench/stop_latency.sh [DELAY] [RUNS] BINARY...
set -euo pipefail
cd "$(dirname "$0")/.."
delay=${1:-1}
runs=${2:-3}
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for ((r = 0; r < runs; ++r)); do
  for bin in "$@"; do
    rm -f "$tmp"/sp.* "$tmp/err"
    "$bin" render scenes/disk_100k.toml --estimator split --spp 65536 -D camera.width=320 -D camera.height=180 \
      -o "$tmp/sp.exr" 2>"$tmp/err" &
    pid=$!
    until grep -q "frame 0" "$tmp/err" 2>/dev/null; do sleep 0.05; done
    sleep "$delay"
    t0=$(date +%s.%N)
    kill -TERM "$pid"
    wait "$pid" || true
    t1=$(date +%s.%N)
    echo "$bin $(echo "$t1 - $t0" | bc)"
  done
done | tee "$tmp/times"
for bin in "$@"; do
  grep -F "$bin " "$tmp/times" | awk '{print $2}' | sort -g | awk -v b="$bin" '{v[NR]=$1} END {printf "%s: median %.2f s of %d\n", b, v[int((NR+1)/2)], NR}'
done
