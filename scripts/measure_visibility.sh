#!/usr/bin/env bash
# The error of the GPU pipeline's visibility rule (TMin = 0.001,
# TMax = d - 0.001) against the exact rule, and the equal-error times of
# exact / tree / power, on the quickstart and the 100K disk at 320x180.
# Writes under out/visibility; prints the figures. About 10 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=./build/accretion
out=out/visibility
mkdir -p "$out"
small=(-D camera.width=320 -D camera.height=180)
seed004=(-D 'render.visibility_rule="offset"' -D 'render.offset_origin="tmin"' -D render.offset_tmin=0.001
         -D 'render.offset_far="absolute"' -D render.offset_far_margin=0.001)
lr_mean() { oiiotool "$1" --ch Lr.R,Lr.G,Lr.B --printstats 2>/dev/null | awk '/Stats Avg/ {print ($3+$4+$5)/3}'; }

# Quickstart: exact, with both rules (deterministic: the difference is the rule alone).
/usr/bin/time -f "%e" -o $out/q.exact.time $bin render scenes/quickstart.toml "${small[@]}" --estimator exact --frames 0:1 --quiet -o $out/q.exact.exr
$bin render scenes/quickstart.toml "${small[@]}" --estimator exact --frames 0:1 --quiet "${seed004[@]}" -o $out/q.seed004.exr
echo "quickstart exact 320x180: $(cat $out/q.exact.time) s"
echo "quickstart seed-004 rule vs exact: $($bin compare $out/q.seed004.exr $out/q.exact.exr --layer Lr | tr '\n' ' ')"
echo "quickstart mean Lr: exact $(lr_mean $out/q.exact.exr), seed-004 rule $(lr_mean $out/q.seed004.exr)"

# 100K disk: exact is too slow here; tree with the same seed under both rules
# draws the same lights, so the difference is the rule's (paired).
$bin render scenes/disk_100k.toml "${small[@]}" --estimator tree --spp 256 --frames 0:1 --quiet -o $out/d.tree.exr
$bin render scenes/disk_100k.toml "${small[@]}" --estimator tree --spp 256 --frames 0:1 --quiet "${seed004[@]}" -o $out/d.seed004.exr
echo "disk_100k seed-004 rule vs exact (tree 256 spp, paired): $($bin compare $out/d.seed004.exr $out/d.tree.exr --layer Lr | tr '\n' ' ')"
echo "disk_100k mean Lr: exact rule $(lr_mean $out/d.tree.exr), seed-004 rule $(lr_mean $out/d.seed004.exr)"

# Equal error: converge tree and power against exact (quickstart) and against
# a tree reference at 0.5% (disk); exact's time is its render time (disk: a
# 1/32 row band, scaled).
$bin converge scenes/quickstart.toml "${small[@]}" --frames 0:1 --reference $out/q.exact.exr \
    --estimators power,tree --budget 40s --seeds 3 --quiet -o $out/q.converge
/usr/bin/time -f "%e" -o $out/d.ref.time $bin render scenes/disk_100k.toml "${small[@]}" --estimator tree --spp 64 \
    --target-stderr 0.5% -D render.max_samples=16384 --frames 0:1 --quiet -o $out/d.ref.exr
$bin converge scenes/disk_100k.toml "${small[@]}" --frames 0:1 --reference $out/d.ref.exr \
    --estimators power,tree --budget 40s --seeds 3 --quiet -o $out/d.converge
/usr/bin/time -f "%e" -o $out/d.exact.time $bin render scenes/disk_100k.toml "${small[@]}" --estimator exact --frames 0:1 \
    --shard 5/11 --quiet -o $out/d.exact.exr
echo "disk_100k tree 0.5% reference: $(cat $out/d.ref.time) s; exact, shard 5/11 (2 of 23 row bands): $(cat $out/d.exact.time) s"
echo "converge CSVs: $out/q.converge.csv $out/d.converge.csv"
