#!/usr/bin/env bash
# The exact 1080p reference of disk_100k frame 0 in 8 row shards (the
# reference of bench/split_1080p.sh): renders shards FIRST..LAST in turn,
# each on every core, starting none that would end after DEADLINE seconds;
# then `accretion merge` once all 8 are there. On a many-core machine with
# no accretion build, BIN may name a carried binary (e.g. "lib/ld-linux-x86-64.so.2
# --library-path lib ./accretion").
#   bench/exact_1080p_shards.sh OUT_DIR [FIRST LAST [DEADLINE]]   (default 0 7 1e9)
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:?usage: bench/exact_1080p_shards.sh OUT_DIR [FIRST LAST [DEADLINE]]}
first=${2:-0} last=${3:-7} deadline=${4:-1000000000}
bin=${BIN:-./build/accretion}
mkdir -p "$dir"
start=$SECONDS longest=0
for i in $(seq "$first" "$last"); do
  if ((SECONDS - start + longest * 11 / 10 > deadline)); then echo "stop before shard $i at $((SECONDS - start)) s"; break; fi
  t0=$SECONDS
  $bin render scenes/disk_100k.toml --quiet --estimator exact -D camera.width=1920 -D camera.height=1080 \
      --frames 0 --shard "$i/8" -o "$dir/disk_100k_1080p.{frame}.exr"
  dt=$((SECONDS - t0)); ((dt > longest)) && longest=$dt
  echo "shard $i/8: $dt s"
done
shards=()
for i in $(seq 0 7); do shards+=("$dir/disk_100k_1080p.0000.shard${i}of8.exr"); done
if ls "$dir"/disk_100k_1080p.0000.shard*of8.acc 2>/dev/null | wc -l | grep -qx 8; then
  $bin merge "${shards[@]}" -o "$dir/disk_100k_1080p.0000.exr"
fi
