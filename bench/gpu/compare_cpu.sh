#!/bin/bash
# The image agreement of the OptiX twin with the CPU renderer (issue 16), on
# this (CPU) machine: import the GPU frames that bench/gpu/run.sh's images
# and restir steps brought back, render the same frames with `accretion
# render`, and compare Lr per pixel (relMSE, identical pixels, pixels within
# 1e-4 relative).
#   bash bench/gpu/compare_cpu.sh IMAGES_DIR RESTIR_DIR OUT.csv
# (IMAGES_DIR, RESTIR_DIR: the images/ and restir/ folders of the archives.)
set -euo pipefail
images=$1 restir=$2 csv=$3
A=${ACCRETION:-build/accretion}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
small=(-D camera.width=320 -D camera.height=180)
echo "case,frame,relMSE,identical,within_1e-4,gpu_frame,cpu_render_s" > "$csv"
compare() {  # name frame gpu.exr cpu.exr cpu_seconds
    local j
    j=$($A compare "$3" "$4" --layer Lr --flip none --json)
    echo "$1,$2,$(echo "$j" | jq -r '[.relMSE, .identical, .within_tolerance] | @csv'),$(basename "$3"),$5" >> "$csv"
}
cp "$images"/*.gpuframe "$restir"/*.gpuframe "$T"/
$A import-gpu "$T"/*.gpuframe > /dev/null
declare -A exact=([quickstart]="" [quickstart_disc]='-D geometry.alpha="disc"'
                  [quickstart_sphere]='-D shading.model="sphere" -D geometry.orientation="view_point"')
for name in quickstart quickstart_disc quickstart_sphere; do
    eval "extra=(${exact[$name]})"
    s0=$(date +%s.%N)
    $A render scenes/quickstart.toml "${small[@]}" -D render.estimator='"exact"' "${extra[@]}" --frames 0:1 \
        -o "$T/cpu_$name.{frame}.exr" --quiet > /dev/null
    compare "exact $name" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr" "$(echo "$(date +%s.%N) - $s0" | bc)"
done
for bc in none basic pairwise; do
    s0=$(date +%s.%N)
    $A render scenes/quickstart.toml "${small[@]}" -D render.estimator='"restir"' -D restir.bias_correction="\"$bc\"" \
        --frames 0:3 -o "$T/cpu_$bc.{frame}.exr" --quiet > /dev/null
    t=$(echo "$(date +%s.%N) - $s0" | bc)
    for f in 0 1 2; do
        compare "restir $bc" $f "$T/$bc.000$f.exr" "$T/cpu_$bc.000$f.exr" "$t"
        [ -f "$T/basic_reorder.000$f.exr" ] && [ $bc = basic ] &&
            compare "restir basic (optixReorder)" $f "$T/basic_reorder.000$f.exr" "$T/cpu_$bc.000$f.exr" "$t"
    done
done
column -s, -t "$csv"
