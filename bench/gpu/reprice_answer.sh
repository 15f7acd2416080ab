#!/bin/bash
# The README answer's four configurations (tune's recommendation and seed
# 004's, 100K and 1M, 1920x1080) priced by `accretion cost` with the
# committed calibration (new) and with a previous coefficients file (old:
# OLD=path), frame 1 after one history frame, as tune prices them.
#   OLD=old_coefficients.json bash bench/gpu/reprice_answer.sh > reprice.csv
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
echo "particles,configuration,calibration,predicted_ms"
REC="-D geometry.layout=\"aabbs\" -D geometry.cluster_size=10000000 -D geometry.build=\"refit\" -D gpu.omm=\"off\" -D render.estimator=\"restir\" -D render.source=\"tree\" -D render.candidates=32 -D restir.spatial_neighbours=0 -D restir.spatial_iterations=1 -D restir.bias_correction=\"pairwise\" -D restir.visibility_reuse=false -D restir.basic_visibility=false -D restir.resolution_scale=0.5"
SEED="-D render.estimator=\"restir\""
for n in 100k 1m; do
  P=""; [ $n = 1m ] && P="-D particles.count=1000000"
  for c in rec seed; do
    [ $c = rec ] && A="$REC" || A="$SEED"
    for cal in new old; do
      G=""; [ $cal = old ] && G="-D gpu.coefficients=\"${OLD:?OLD=previous coefficients file}\""
      eval ./build/accretion cost scenes/disk_100k.toml -D camera.width=1920 -D camera.height=1080 $P $A $G --frames 1 --history 1 --overhead 0 --cluster-sizes '""' --omm-levels '""' --ser-keys hit -q -o $OUT/${n}_${c}_${cal}.json > /dev/null
      python3 -c "import json; j=json.load(open('$OUT/${n}_${c}_${cal}.json')); print('$n,$c,$cal,%.3f' % j['predicted_ms'])"
    done
  done
done
