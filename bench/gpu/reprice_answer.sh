#!/bin/bash
# The README answer's four configurations (tune's recommendation, read from
# its JSON in bench/gpu/results/tune/, and seed 004's; 100K and 1M,
# 1920x1080) priced by `accretion cost` with the committed calibration
# (new) and with a previous coefficients file (old: OLD=path), frame 1
# after one history frame, as tune prices them.
#   OLD=old_coefficients.json bash bench/gpu/reprice_answer.sh > reprice.csv
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
echo "particles,configuration,calibration,predicted_ms"
for n in 100k 1m; do
  P=(); [ $n = 1m ] && P=(-D particles.count=1000000)
  mapfile -t rec < <(jq -r '.recommended.defines[] | "-D", .' "bench/gpu/results/tune/disk_${n}_1080p.json")
  for c in rec seed; do
    A=(-D render.estimator=restir); [ $c = rec ] && A=("${rec[@]}")
    for cal in new old; do
      G=(); [ $cal = old ] && G=(-D "gpu.coefficients=${OLD:?OLD=previous coefficients file}")
      ./build/accretion cost scenes/disk_100k.toml -D camera.width=1920 -D camera.height=1080 "${P[@]}" "${A[@]}" "${G[@]}" \
          --frames 1 --history 1 --overhead 0 --cluster-sizes "" --omm-levels "" --ser-keys hit -q -o "$OUT/${n}_${c}_${cal}.json" > /dev/null
      echo "$n,$c,$cal,$(jq -r '.predicted_ms * 1000 | round / 1000' "$OUT/${n}_${c}_${cal}.json")"
    done
  done
done
