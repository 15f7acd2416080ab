#!/usr/bin/env bash
# The anatomy of the error at the engine's operating point: disk_100k (or
# PARTICLES) at 1920x1080, frame 20 after restir's steady-state history (20
# frames: temporal reuse to its M cap), on tune's stratified crops (4x2
# strata, one 160x90 crop each at tune's drawn place, restir with 32 pixels
# of margin), SEEDS seeds, against split references at 1024 spp, with every
# light visible as well (visibility's share). One bias run per configuration
# of the GPU team's choice: seed 004's pipeline, tune's earlier
# recommendation, and tree candidates with each kind of reuse alone.
#   bash bench/operating_point.sh [PARTICLES] [SEEDS] [OUT]   (100000, 8, bench/results/operating_point_<N>)
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-100000} seeds=${2:-8} out=${3:-bench/results/operating_point_$n}
A=${ACCRETION:-build/accretion}
scene=scenes/disk_100k.toml
D=(-D camera.width=1920 -D camera.height=1080 -D particles.count=$n)
mkdir -p "$out"
# tune's crops (cmd_tune.cpp errorCrops), printed by tune itself would need a
# whole search: the same strata and hash here.
crops=$(python3 - <<'PY'
M = (1 << 64) - 1
def mix64(x):
    x = (x + 0x9e3779b97f4a7c15) & M
    x = ((x ^ (x >> 30)) * 0xbf58476d1ce4e5b9) & M
    x = ((x ^ (x >> 27)) * 0x94d049bb133111eb) & M
    return x ^ (x >> 31)
cols, rows, cw, ch, W, H = 4, 2, 160, 90, 1920, 1080
sw, sh = W // cols, H // rows
for r in range(rows):
    for c in range(cols):
        h = mix64((0x9e3779b97f4a7c15 * (r * cols + c + 1)) & M)
        x0 = c * sw + (h & 0xffffffff) % (sw - cw + 1)
        y0 = r * sh + (h >> 32) % (sh - ch + 1)
        print(f"[{x0},{x0 + cw},{y0},{y0 + ch}]")
PY
)
refs=() unshadowed=() k=0
for c in $crops; do
    for vis in true false; do
        f=$out/ref$k.$vis.exr
        [ -f "$f" ] || "$A" render $scene "${D[@]}" -D "render.crop=$c" -D shading.visibility=$vis --estimator split --spp 1024 \
            --frames 20:21 -o "$f" --quiet > /dev/null
    done
    refs+=(--reference "$out/ref$k.true.exr")
    unshadowed+=(--unshadowed-reference "$out/ref$k.false.exr")
    k=$((k + 1))
done
run() {  # NAME SPEC
    local t0=$SECONDS
    "$A" bias $scene "${D[@]}" "${refs[@]}" "${unshadowed[@]}" --frame 20 --seeds "$seeds" --estimators "$2" -q -o "$out/$1" \
        > "$out/$1.txt"
    echo "$1: $((SECONDS - t0)) s" | tee -a "$out/times.txt"
}
: > "$out/times.txt"
run seed004 "restir:basic:render.source=uniform:render.candidates=16"
run recommended_before "restir:pairwise:render.source=tree:render.candidates=32:restir.spatial_neighbours=0:restir.resolution_scale=0.5"
run tree8_no_reuse "restir:pairwise:render.source=tree:render.candidates=8:restir.spatial_neighbours=0:restir.temporal=false"
run tree8_temporal "restir:pairwise:render.source=tree:render.candidates=8:restir.spatial_neighbours=0"
run tree8_spatial "restir:pairwise:render.source=tree:render.candidates=8:restir.temporal=false"
run tree8_both "restir:pairwise:render.source=tree:render.candidates=8"
run tree32_temporal "restir:pairwise:render.source=tree:render.candidates=32:restir.spatial_neighbours=0"
echo "commit $(git rev-parse --short=10 HEAD), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)" >> "$out/times.txt"
python3 scripts/operating_point_table.py "$out" > "$out/table.md"
cat "$out/table.md"
