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
source bench/operating_point_refs.sh
run() {  # NAME SPEC
    local t0=$SECONDS
    "$A" bias $scene "${D[@]}" "${refs[@]}" "${unshadowed[@]}" --frame "${FRAME:-20}" --seeds "$seeds" --estimators "$2" -q -o "$out/$1" \
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
