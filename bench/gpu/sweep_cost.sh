#!/bin/bash
# The counters of the cost-model sweep (bench/gpu/sweep.txt, and the layout
# rows of bench/gpu/layouts.txt), here on the CPU: `accretion cost` of each
# configuration's frame 1 (one history frame, as the twin's timed frame), one
# counters CSV for `accretion calibrate`.
#   bash bench/gpu/sweep_cost.sh OUT_DIR [LIST...]   -> OUT_DIR/counters.csv
# (LIST: configuration files, by default bench/gpu/sweep.txt bench/gpu/layouts.txt;
# a configuration whose .cost.csv is there already is not counted again.)
set -euo pipefail
OUT=${1:?usage: sweep_cost.sh OUT_DIR [LIST...]}
shift
LISTS=("$@")
[ ${#LISTS[@]} -gt 0 ] || LISTS=(bench/gpu/sweep.txt bench/gpu/layouts.txt)
BIN=${ACCRETION:-build/accretion}
mkdir -p "$OUT"
cat "${LISTS[@]}" | grep -v '^#' | while read -r name args; do
    [ -z "$name" ] && continue
    [ -f "$OUT/$name.cost.csv" ] && continue
    # shellcheck disable=SC2086  # the overrides are words
    "$BIN" cost scenes/disk_100k.toml -D render.estimator=restir $args --frames 1 --history 1 --overhead 0 \
        --cluster-sizes "" --omm-levels "" --ser-keys hit --config "$name" -q -o "$OUT/$name.cost.json" > /dev/null < /dev/null
    echo "cost: $name" >&2
done
# The sweep's timings (results/sweep_timings.csv) are of a twin that timed a
# pass's runs together (spatialResampling over its iterations; the twin now
# times each run apart, as "spatialResampling[2]", and sum_runs.py sums
# those timings likewise): the counters of spatialResampling[2]... are added
# to spatialResampling's to join them.
python3 bench/gpu/sum_runs.py "$OUT"/*.cost.csv > "$OUT/counters.csv"
echo "$OUT/counters.csv"
