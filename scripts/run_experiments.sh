#!/usr/bin/env bash
# Regenerates the issue-3 experiments (CSV, JSON, PNG plots, bias maps) under
# out/experiments. Nothing here is committed output: run it to get the plots.
#   scripts/run_experiments.sh [all|reference|converge|table|bias|sequence]
# Times on the project's 2-core AMD EPYC VM at commits 8bd5a6c and 171b6fd: all ~19 min
# (references ~8 min, converge ~7 min, table ~2 min, bias ~2 min, sequence ~20 s).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=./build/accretion
out=out/experiments
mkdir -p "$out"
what=${1:-all}

disk=scenes/disk_100k.toml
quick=scenes/quickstart.toml

if [[ $what == all || $what == reference ]]; then
  # Unbiased references with their per-pixel standard error (Lr_stderr).
  $bin render $disk --estimator tree --spp 64 --target-stderr 1% -D render.max_samples=4096 \
      --frames 8:9 -o $out/disk_100k.ref.exr
  $bin render $quick --estimator tree --spp 64 --target-stderr 0.5% -D render.max_samples=4096 \
      --frames 8:9 -o $out/quickstart.ref.exr
  # 32 frames at 320x180 for the sequence experiment.
  $bin render $quick -D camera.width=320 -D camera.height=180 --estimator tree --spp 512 \
      --frames 0:32 -o "$out/seq/ref.{frame}.exr"
fi

if [[ $what == all || $what == converge ]]; then
  # Error against time: uniform MC, power, tree, ris and restir (each bias mode, with and
  # without visibility reuse) on frame 8 of the 100K disk at 1280x720, after 8 frames of history.
  # Each point is the mean error of 3 seeds (median time).
  $bin converge $disk --frames 8:9 --reference $out/disk_100k.ref.exr --history 8 --budget 60s --seeds 3 \
      --estimators uniform,power,tree,ris,restir:none,restir:basic,restir:pairwise,restir:none:restir.visibility_reuse=true,restir:basic+vis:restir.visibility_reuse=true,restir:pairwise:restir.visibility_reuse=true \
      -o $out/disk_100k.converge
fi

if [[ $what == all || $what == table ]]; then
  # The restir variants at the scene's defaults (16 candidates), mean of 5 seeds, for the summary table.
  $bin converge $disk --frames 8:9 --reference $out/disk_100k.ref.exr --history 8 --seeds 5 \
      --min-effort 16 --max-effort 16 \
      --estimators uniform,restir:none,restir:basic,restir:pairwise,restir:none:restir.visibility_reuse=true,restir:basic+vis:restir.visibility_reuse=true,restir:pairwise:restir.visibility_reuse=true \
      -o $out/disk_100k.table
fi

if [[ $what == all || $what == bias ]]; then
  # Mean signed error over 64 seeds against the tree reference (which carries its own error).
  $bin bias $quick --frames 8:9 --reference $out/quickstart.ref.exr --seeds 64 --history 4 -D render.samples=16 \
      --estimators uniform,ris,restir:none,restir:basic,restir:pairwise,restir:none:restir.visibility_reuse=true,restir:basic+vis:restir.visibility_reuse=true,restir:pairwise:restir.layout=\"packed\":restir.light_bits=14,restir:pairwise:restir.resolution_scale=0.5 \
      -o $out/quickstart.bias
fi

if [[ $what == all || $what == sequence ]]; then
  # Error per frame over 32 animated frames: temporal reuse converging, and the M cap.
  $bin converge $quick -D camera.width=320 -D camera.height=180 --frames 0:1 --sequence 32 --seeds 8 \
      --reference "$out/seq/ref.{frame}.exr" \
      --estimators restir:pairwise:restir.temporal=false,restir:pairwise:restir.m_cap=1,restir:pairwise:restir.m_cap=5,restir:pairwise,restir:none \
      -o $out/quickstart.sequence
fi
