#!/usr/bin/env bash
# What a texel history's bias is made of at disk_100k's operating point
# (docs/designs.md, "What the long history's bias is"): its lag, measured by
# `accretion lag` on frames 0-48 of each visible particle's light at its
# texel's centre with little noise (particle_split, its 64 nearest lights
# summed, 256 far rays of 4 candidates each, no history), over tune's eight
# crops (bench/operating_point_refs.sh's split references at frame 48):
# the whole light (what a history of every term averages) and the far light
# (the whole less a render of the 16 nearest lights alone: what history_of
# far averages); and the bias of one texel a particle without any history,
# that estimator's at frame 48 against the same references (2 seeds).
#
#   bash bench/history_lag.sh [OUT]    (default bench/results/history_lag_100000)
#
# The 98 frames (2 GB) go to FRAMES (default out/history_lag) and are kept:
# a second run measures again without rendering. About 30 min on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-bench/results/history_lag_100000}
frames=${FRAMES:-out/history_lag}
A=${ACCRETION:-build/accretion}
scene=scenes/disk_100k.toml
D=(-D camera.width=1920 -D camera.height=1080 -D render.estimator=particle_split)
centre=(-D particle_split.near=64 -D particle_split.far=256 -D particle_split.candidates=4)
mkdir -p "$out" "$frames"
[ -f "$frames/whole.0048.exr" ] || "$A" render $scene "${D[@]}" "${centre[@]}" --frames 0:49 -q -o "$frames/whole.{frame}.exr" > /dev/null
[ -f "$frames/near16.0048.exr" ] || "$A" render $scene "${D[@]}" -D particle_split.near=16 -D particle_split.far=0 --frames 0:49 -q \
    -o "$frames/near16.{frame}.exr" > /dev/null
REFS=${REFS:-bench/results/operating_point_100000_f48} FRAME=48 source bench/operating_point_refs.sh
windows=()
for ((k = 0; k < ${#refs[@]}; k += 2)); do windows+=("${refs[k + 1]}"); done
{
    echo "# the whole light's history (every term averaged), over tune's eight crops"
    "$A" lag "$frames/whole.{frame}.exr" --frames 0:49 --history 0.5,0.75,0.9,0.95 --windows-of "${windows[@]}" -q \
        --csv "$out/trend_crops.csv"
    echo "# the far light's history (history_of far, near 16; each frame's own near set, as without far_handoff)"
    "$A" lag "$frames/whole.{frame}.exr" --frames 0:49 --history 0.5,0.75,0.9,0.95 --windows-of "${windows[@]}" -q \
        --subtract "$frames/near16.{frame}.exr"
    echo "# the whole light's history over the whole frame"
    "$A" lag "$frames/whole.{frame}.exr" --frames 0:49 --history 0.5,0.75,0.9,0.95 -q --csv "$out/trend_frame.csv"
} | tee "$out/lag.txt"
spec=particle_split:particle_split.near=64:particle_split.far=256:particle_split.candidates=4
"$A" bias $scene -D camera.width=1920 -D camera.height=1080 "${refs[@]}" --frame 48 --seeds 2 --estimators "$spec" -q \
    -o "$out/one_texel" | tee "$out/one_texel.txt"
echo "commit $(git rev-parse --short=10 HEAD), $(nproc) cores: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)" | tee "$out/machine.txt"
