#!/usr/bin/env bash
# `accretion cost` of every bench/gpu/designs.txt configuration of one size
# (100k or 1m), or of designs_cluster.txt (cluster: scenes/cluster_150k.toml),
# as the twin timed it (frame 1 after a history frame), into
# OUT/cost_<config>.json; then bench/gpu/designs_priced.py prices them
# against the twin's ms.
#   bash bench/gpu/designs_cost.sh [100k|1m|cluster] [OUT] [NAMES]   (100k, out/designs_cost; NAMES: a regex of
#   the configurations counted again, every one by default)
set -euo pipefail
cd "$(dirname "$0")/../.."
size=${1:-100k} out=${2:-out/designs_cost} names=${3:-.}
A=${ACCRETION:-build/accretion}
mkdir -p "$out"
list=bench/gpu/designs.txt scene=scenes/disk_100k.toml
if [ "$size" = cluster ]; then list=bench/gpu/designs_cluster.txt scene=scenes/cluster_150k.toml; python3 scenes/cluster/make_cluster.py 3; fi
grep -v '^#' "$list" | sed 's/ *#.*//' | grep "_$size " | grep -E "^($names)" | while read -r name args; do
    # shellcheck disable=SC2086  # the overrides are words; the twin's run.sh sets restir first, as here
    "$A" cost "$scene" -D render.estimator=restir $args --frames 1:2 --history 1 --overhead 0 --omm-levels "" \
        --cluster-sizes "" --ser-keys hit --config "$name" -q -o "$out/cost_$name.json" > "$out/cost_$name.log"
done
python3 bench/gpu/designs_priced.py "$out"
