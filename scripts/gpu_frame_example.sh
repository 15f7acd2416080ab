#!/usr/bin/env bash
# docs/gpu-frame-loop.md's worked example, end to end: an engine's camera file (an orbit
# with TAA jitter, as a CSV), the exact reference of its frames, "GPU"
# frames (restir at the GPU pipeline's settings stands in for the engine's
# output), compare with error maps, a sequence with flicker, one pixel
# explained. Writes the pictures docs/gpu-frame-loop.md shows into docs/gpu_frame_loop/.
# Usage: bash scripts/gpu_frame_example.sh [BUILD_DIR]   (from the repository root)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${1:-build}/accretion
W=out/gpu_frame_example
DOCS=docs/gpu_frame_loop
mkdir -p "$W" "$DOCS"

# 1. The engine's cameras: 4 frames of a camera creeping round the disk (0.05 degrees a
#    frame), with Halton(2,3) TAA jitter in pixels.
awk 'BEGIN {
    print "# convention = d3d"
    print "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z,up_x,up_y,up_z,fov,jitter_x,jitter_y"
    split("0.5 0.25 0.75 0.125", hx, " "); split("0.3333333 0.6666667 0.1111111 0.4444444", hy, " ")
    for (f = 0; f < 4; ++f) {
        a = f * 0.05 * 3.14159265 / 180.0
        printf "%d,%.6f,7,%.6f,0,0,0,0,1,0,45,%.4f,%.4f\n", f, 17 * sin(a), 17 * cos(a), hx[f + 1] - 0.5, hy[f + 1] - 0.5
    }
}' > "$W/cams.csv"
# One fixed preview exposure for both, so that the previews compare side by side
# (auto exposure would expose each image by its own median).
SCENE=(scenes/quickstart.toml -D camera.file=\""$PWD/$W/cams.csv"\" -D camera.width=320 -D camera.height=180
       -D render.auto_exposure=false -D render.exposure=2)

# 2. The reference of every frame (exact), and 3. the "GPU" frames.
"$BIN" render "${SCENE[@]}" --quiet --estimator exact --frames 0:4 -o "$W/ref.{frame}.exr" > "$W/ref.log"
"$BIN" render "${SCENE[@]}" --quiet --estimator restir --frames 0:4 -o "$W/gpu.{frame}.exr" > "$W/gpu.log"

# 4. One frame: metrics, error maps (signed, relative, FLIP) with colour bars.
"$BIN" compare "$W/gpu.0003.exr" "$W/ref.0003.exr" --error-map "$W/err.exr" | tee "$W/compare.txt"

# 5. The sequence: per-frame CSV and plot (relMSE, FLIP, flicker).
"$BIN" compare "$W/gpu.{frame}.exr" "$W/ref.{frame}.exr" --frames 0:4 --csv "$W/sequence.csv" | tee "$W/sequence.txt"

# 6. One pixel of the reference, explained: the brightest term first.
"$BIN" render "${SCENE[@]}" --quiet --estimator exact --frames 3 --pixel 200,100 > "$W/pixel.txt"
head -12 "$W/pixel.txt"

for f in ref.0003.png gpu.0003.png err.relative.png err.flip.png sequence.png; do cp "$W/$f" "$DOCS/$f"; done
cp "$W/cams.csv" "$W/compare.txt" "$W/sequence.txt" "$W/pixel.txt" "$DOCS/"
echo "pictures and outputs in $DOCS (made by $(git rev-parse --short HEAD 2>/dev/null || echo '?') with $BIN)"
