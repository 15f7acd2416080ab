#!/usr/bin/env bash
# restir's pass times of one configuration, binaries side by side: disk_100k
# at 1920x1080, light tree candidates (M = $CANDIDATES, default 32), temporal
# reuse, frames 0..3 (the last three timed), RUNS runs per binary
# interleaved; prints each binary's median seconds per frame of every pass
# and of the frame.
#   bash bench/restir_passes.sh RUNS BINARY...
set -euo pipefail
cd "$(dirname "$0")/.."
runs=${1:?usage: bench/restir_passes.sh RUNS BINARY...}
shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for ((r = 0; r < runs; ++r)); do
  k=0
  for bin in "$@"; do
    "$bin" render scenes/disk_100k.toml --quiet --estimator restir --frames 0:4 -D render.source=tree \
      -D render.candidates="${CANDIDATES:-32}" -D restir.spatial_neighbours=0 -D camera.width=1920 -D camera.height=1080 \
      -o "$tmp/b$k.r$r.{frame}.exr" >/dev/null
    k=$((k + 1))
  done
done
python3 - "$tmp" "$runs" "$@" <<'PY'
import json, statistics, sys
tmp, runs, bins = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
table = {}
for k, b in enumerate(bins):
    per = {}
    for r in range(runs):
        frames = json.load(open(f"{tmp}/b{k}.r{r}.stats.json"))["frames"][1:]
        for name in frames[0]["passes"]:
            per.setdefault(name, []).append(sum(f["passes"][name] for f in frames) / len(frames))
        per.setdefault("frame", []).append(sum(f["seconds"] for f in frames) / len(frames))
    table[b] = {n: statistics.median(v) for n, v in per.items()}
names = sorted({n for t in table.values() for n in t}, key=lambda n: (n == "frame", n))
print(f"{'pass':<22}" + "".join(f"{b[-28:]:>30}" for b in bins))
for n in names:
    print(f"{n:<22}" + "".join(f"{table[b].get(n, float('nan')):>30.4f}" for b in bins))
PY
