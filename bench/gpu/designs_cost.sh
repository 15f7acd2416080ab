#!/usr/bin/env bash
# `accretion cost` of every bench/gpu/designs.txt configuration of one size
# (100k or 1m), as the twin timed it (frame 1 after a history frame), into
# OUT/cost_<config>.json; then bench/gpu/designs_priced.py prices them
# against the twin's ms.
#   bash bench/gpu/designs_cost.sh [100k|1m] [OUT]   (100k, out/designs_cost)
set -euo pipefail
cd "$(dirname "$0")/../.."
size=${1:-100k} out=${2:-out/designs_cost}
A=${ACCRETION:-build/accretion}
mkdir -p "$out"
grep -v '^#' bench/gpu/designs.txt | sed 's/ *#.*//' | grep "_$size " | while read -r name args; do
    # shellcheck disable=SC2086  # the overrides are words; the twin's run.sh sets restir first, as here
    "$A" cost scenes/disk_100k.toml -D render.estimator=restir $args --frames 1:2 --history 1 --overhead 0 --omm-levels "" \
        --cluster-sizes "" --ser-keys hit --config "$name" -q -o "$out/cost_$name.json" > "$out/cost_$name.log"
done
python3 bench/gpu/designs_priced.py "$out"
