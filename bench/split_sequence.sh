#!/usr/bin/env bash
# The 64-frame reference sequence: disk_100k frames 0..63 at 1920x1080,
# `split` at SPP samples with k from each frame's pilot.
#   bench/split_sequence.sh time SPP OUTDIR
#       one `render --frames 0:64` (seed 1), its wall time: the figure
#   bench/split_sequence.sh pairs SPP OUTDIR [JOBS THREADS]
#       every frame with seeds 1 and 2 (JOBS renders of THREADS threads at
#       a time), `compare` of each pair: OUTDIR/pairs.csv
# There are no exact references for frames 1-63: the pair's relMSE of A
# against B, halved, estimates each frame's relMSE (the estimator is
# unbiased; B's noise in the denominator makes it read high: calibrate it
# on frame 0 against the exact reference, bench/README.md).
# ACCRETION (default ./build/accretion) may be a command, e.g. a carried
# binary run through its own loader; FRAMES, W and H (default 64, 1920,
# 1080) shrink the run for a smoke test.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?usage: bench/split_sequence.sh time|pairs SPP OUTDIR [JOBS THREADS]}
spp=${2:?SPP}
out=${3:?OUTDIR}
B=${ACCRETION:-./build/accretion}
mkdir -p "$out"
frames=${FRAMES:-64}
render=(render scenes/disk_100k.toml --quiet --estimator split --spp "$spp" -D camera.width="${W:-1920}" -D camera.height="${H:-1080}")
case "$mode" in
time)
  start=$(date +%s%N)
  $B "${render[@]}" --seed 1 --frames "0:$frames" -o "$out/s1.{frame}.exr" > /dev/null
  echo "$frames frames, $spp spp: $(( ($(date +%s%N) - start) / 1000000 )) ms" | tee "$out/time.txt"
  ;;
pairs)
  jobs=${4:-1} threads=${5:-0}
  export B spp out threads
  export RENDER="${render[*]}"
  one() {
    $B $RENDER --seed "$1" --frames "$2:$(($2 + 1))" --threads "$threads" -o "$out/s$1.f$2.{frame}.exr" > /dev/null
  }
  export -f one
  for f in $(seq 0 $((frames - 1))); do for s in 1 2; do echo "$s $f"; done; done | xargs -P "$jobs" -n 2 bash -c 'one "$@"' _
  echo "frame,near_lights,pair_relMSE_half" > "$out/pairs.csv"
  for f in $(seq 0 $((frames - 1))); do
    n=$(printf %04d "$f")
    rel=$($B compare "$out/s1.f$f.$n.exr" "$out/s2.f$f.$n.exr" --layer Lr --flip none --json 2>/dev/null |
          python3 -c 'import json,sys; print(json.load(sys.stdin)["relMSE"] / 2)')
    k=$(python3 -c "import json; print(json.load(open('$out/s1.f$f.stats.json'))['frames'][0]['counts']['near_lights'])")
    echo "$f,$k,$rel" >> "$out/pairs.csv"
  done
  python3 - "$out/pairs.csv" <<'PY'
import csv, statistics, sys
e = [float(r["pair_relMSE_half"]) for r in csv.DictReader(open(sys.argv[1]))]
print(f"pair relMSE / 2 over {len(e)} frames: mean {statistics.mean(e):.4g}, min {min(e):.4g}, max {max(e):.4g}")
PY
  ;;
*) echo "bench/split_sequence.sh: unknown mode $mode (time or pairs)" >&2; exit 2 ;;
esac
