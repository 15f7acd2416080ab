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
echo "case,frame,relMSE,identical,within_1e-4,gpu_frame,against" > "$csv"
compare() {  # name frame gpu.exr other.exr
    local j
    j=$($A compare "$3" "$4" --layer Lr --flip none --json)
    echo "$1,$2,$(echo "$j" | jq -r '[.relMSE, .identical, .within_tolerance] | @csv'),$(basename "$3"),$(basename "$4")" >> "$csv"
}
cpu() {  # output-stem frames overrides...: the CPU's frames of the same settings
    local stem=$1 frames=$2
    shift 2
    $A render scenes/quickstart.toml "${small[@]}" "$@" --frames "$frames" -o "$T/cpu_$stem.{frame}.exr" --quiet > /dev/null
}
cp "$images"/*.gpuframe "$restir"/*.gpuframe "$T"/
$A import-gpu "$T"/*.gpuframe > /dev/null
disc=(-D geometry.alpha=disc)

# exact: GPU frame stem, then the CPU's overrides.
declare -A exact=(
    [quickstart]="" [quickstart_disc]="${disc[*]}"
    [quickstart_sphere]="-D shading.model=sphere -D geometry.orientation=view_point"
    [quickstart_omm4state_l2]="${disc[*]} -D gpu.omm=4state -D gpu.omm_level=2"
    [quickstart_omm4state_l4]="${disc[*]} -D gpu.omm=4state -D gpu.omm_level=4"
    [quickstart_omm4state_l6]="${disc[*]} -D gpu.omm=4state -D gpu.omm_level=6"
    [quickstart_omm2state_l4]="${disc[*]} -D gpu.omm=2state -D gpu.omm_level=4"
    [quickstart_offset]="-D render.visibility_rule=offset"
    [quickstart_disc_offset]="${disc[*]} -D render.visibility_rule=offset")
for name in quickstart quickstart_disc quickstart_sphere quickstart_omm4state_l2 quickstart_omm4state_l4 \
            quickstart_omm4state_l6 quickstart_omm2state_l4 quickstart_offset quickstart_disc_offset; do
    # shellcheck disable=SC2086  # the overrides are words
    cpu "$name" 0:1 -D render.estimator=exact ${exact[$name]}
    compare "exact $name" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr"
done
# A 4-state micromap leaves the any-hit's image; the offset rule's own error against exact.
for l in 2 4 6; do compare "exact omm4 L$l (GPU) vs any-hit (GPU)" 0 "$T/quickstart_omm4state_l$l.0000.exr" "$T/quickstart_disc.0000.exr"; done
compare "exact omm2 L4 (GPU) vs any-hit (CPU)" 0 "$T/quickstart_omm2state_l4.0000.exr" "$T/cpu_quickstart_disc.0000.exr"
compare "offset rule (GPU) vs exact rule (CPU)" 0 "$T/quickstart_offset.0000.exr" "$T/cpu_quickstart.0000.exr"
compare "offset rule with disc alpha (GPU) vs exact rule (CPU)" 0 "$T/quickstart_disc_offset.0000.exr" "$T/cpu_quickstart_disc.0000.exr"

# restir, frames 0-2: GPU stem, CPU stem, CPU overrides.
restir_case() {
    local gpu=$1 cpuStem=$2
    shift 2
    [ -f "$T/cpu_$cpuStem.0000.exr" ] || cpu "$cpuStem" 0:3 -D render.estimator=restir "$@"
    for f in 0 1 2; do compare "restir $gpu" $f "$T/$gpu.000$f.exr" "$T/cpu_$cpuStem.000$f.exr"; done
}
for bc in none basic pairwise; do restir_case "$bc" "$bc" -D restir.bias_correction=$bc; done
restir_case basic_reorder basic
restir_case basic_scale0.5 basic_scale0.5 -D restir.resolution_scale=0.5
restir_case basic_scale0.75 basic_scale0.75 -D restir.resolution_scale=0.75
restir_case basic_omm4 basic_omm4 "${disc[@]}" -D gpu.omm=4state -D gpu.omm_level=4
restir_case basic_omm4_traverse basic_omm4
column -s, -t "$csv"
