#!/bin/bash
# The counters of the cost-model sweep (bench/gpu/sweep.txt), here on the CPU:
# `accretion cost` of each configuration's frame 1 (one history frame, as the
# twin's timed frame), one counters CSV for `accretion calibrate`.
#   bash bench/gpu/sweep_cost.sh OUT_DIR      -> OUT_DIR/counters.csv
set -euo pipefail
OUT=${1:?usage: sweep_cost.sh OUT_DIR}
BIN=${ACCRETION:-build/accretion}
mkdir -p "$OUT"
grep -v '^#' bench/gpu/sweep.txt | while read -r name args; do
    [ -z "$name" ] && continue
    # shellcheck disable=SC2086  # the overrides are words
    "$BIN" cost scenes/disk_100k.toml -D render.estimator=restir $args --frames 1 --history 1 --overhead 0 \
        --cluster-sizes "" --omm-levels "" --ser-keys hit --config "$name" -q -o "$OUT/$name.cost.json" > /dev/null < /dev/null
    echo "cost: $name" >&2
done
{ head -1 "$(ls "$OUT"/*.cost.csv | head -1)"; for f in "$OUT"/*.cost.csv; do tail -n +2 "$f"; done; } > "$OUT/counters.csv"
echo "$OUT/counters.csv"
