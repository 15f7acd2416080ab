#!/usr/bin/env bash
# The error of issue 46's designs at the engine's operating point, measured
# as bench/operating_point.sh measures restir's (its crops and its split
# references at 1024 spp, made here when absent): disk_100k (or PARTICLES)
# at 1920x1080, frame 20 after 20 history frames, tune's eight 160x90 crops,
# SEEDS seeds; each bias run beside the GPU ms the twin measured for the
# same configuration (bench/gpu/results/designs.csv). The configurations
# are bench/gpu/designs.txt's lighting (the geometry changes the time, not
# the image). PARTICLES "cluster": cluster_150k (raw buffers from
# scenes/cluster/make_cluster.py, made here when absent) and the
# configurations of bench/gpu/designs_cluster.txt. FRAME=48 measures frame
# 48 instead (its references in OUT, which must then be another folder):
# the steady state of a texel history longer than 20 frames. REFS=DIR reads
# the references from DIR (bench/operating_point_refs.sh). BIAS_ARGS are
# passed to each bias run as they are (e.g. "--age-frames 16").
#   bash bench/designs.sh [PARTICLES|cluster] [SEEDS] [OUT] [NAME...]   (100000, 8, bench/results/operating_point_<N>; all)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-100000} seeds=${2:-8} out=${3:-bench/results/operating_point_$n}
shift $(($# < 3 ? $# : 3))
A=${ACCRETION:-build/accretion}
scene=scenes/disk_100k.toml list=bench/gpu/designs.txt suffix=100k
D=(-D camera.width=1920 -D camera.height=1080 -D particles.count=$n)
if [ "$n" = 1000000 ]; then suffix=1m; fi
if [ "$n" = cluster ]; then
    scene=scenes/cluster_150k.toml list=bench/gpu/designs_cluster.txt suffix=cluster
    D=(-D camera.width=1920 -D camera.height=1080)
    [ -f scenes/cluster/frames/c.0020.bin ] || python3 scenes/cluster/make_cluster.py
fi
mkdir -p "$out"
source bench/operating_point_refs.sh
: >> "$out/times.txt"
# the list's lines of this size: name, then the lighting overrides as a bias spec.
grep -v '^#' "$list" | sed 's/ *#.*//' | grep "_$suffix " | while read -r name args; do
    base=${name%_"$suffix"}
    if [ $# -gt 0 ] && [[ " $* " != *" $base "* ]]; then continue; fi
    spec=$(python3 - "$args" <<'PY'
import sys
words = sys.argv[1].split()
kv = [words[i + 1] for i in range(0, len(words), 2) if words[i] == "-D"]
lighting = [x for x in kv if x.split("=")[0].split(".")[0] in ("render", "restir", "voxel", "particle_split")]
est = next((x.split("=")[1] for x in lighting if x.startswith("render.estimator=")), "restir")
print(":".join([est] + [x for x in lighting if not x.startswith("render.estimator=")]))
PY
)
    t0=$SECONDS
    "$A" bias $scene "${D[@]}" "${refs[@]}" "${unshadowed[@]}" --frame "${FRAME:-20}" --seeds "$seeds" --estimators "$spec" ${BIAS_ARGS:-} -q \
        -o "$out/design_$base" > "$out/design_$base.txt"
    echo "design_$base: $((SECONDS - t0)) s ($seeds seeds)" | tee -a "$out/times.txt"
done
echo "commit $(git rev-parse --short=10 HEAD), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)" >> "$out/times.txt"
python3 scripts/operating_point_table.py "$out" > "$out/table.md"
cat "$out/table.md"
