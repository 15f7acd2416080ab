#!/bin/bash
# The image agreement of the OptiX twin with the CPU renderer, on
# this (CPU) machine: import the GPU frames that bench/gpu/run.sh's images,
# restir and sampling steps brought back, render the same frames with
# `accretion render`, and compare Lr per pixel (relMSE, identical pixels,
# pixels within 1e-4 relative); for uniform and power also the standard
# error and the samples taken (adaptive sampling's stops).
#   bash bench/gpu/compare_cpu.sh OUT.csv DIR...
# (DIR: the images/, restir/ or sampling/ folders of the archives; the cases
# whose GPU frames are there are compared.)
set -euo pipefail
csv=$1
shift
A=${ACCRETION:-build/accretion}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
small=(-D camera.width=320 -D camera.height=180)
echo "case,frame,relMSE,identical,within_1e-4,gpu_frame,against" > "$csv"
compare() {  # name frame gpu.exr other.exr [compare's channel option]
    local j
    [ -f "$3" ] || return 0  # a case whose GPU frames were not brought
    # shellcheck disable=SC2086  # the option is words
    j=$($A compare "$3" "$4" ${5:---layer Lr} --flip none --json)
    echo "$1,$2,$(echo "$j" | jq -r '[.relMSE, .identical, .within_tolerance] | @csv'),$(basename "$3"),$(basename "$4")" >> "$csv"
}
cpu() {  # output-stem frames overrides...: the CPU's frames of the same settings
    local stem=$1 frames=$2
    shift 2
    $A render scenes/quickstart.toml "${small[@]}" "$@" --frames "$frames" -o "$T/cpu_$stem.{frame}.exr" --quiet > /dev/null
}
for d in "$@"; do cp "$d"/*.gpuframe "$T"/; done
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
    [ -f "$T/$name.0000.exr" ] || continue
    # shellcheck disable=SC2086  # the overrides are words
    cpu "$name" 0:1 -D render.estimator=exact ${exact[$name]}
    compare "exact $name" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr"
done
# A 4-state micromap leaves the any-hit's image; the offset rule's own error against exact.
for l in 2 4 6; do compare "exact omm4 L$l (GPU) vs any-hit (GPU)" 0 "$T/quickstart_omm4state_l$l.0000.exr" "$T/quickstart_disc.0000.exr"; done
compare "exact omm2 L4 (GPU) vs any-hit (CPU)" 0 "$T/quickstart_omm2state_l4.0000.exr" "$T/cpu_quickstart_disc.0000.exr"
compare "offset rule (GPU) vs exact rule (CPU)" 0 "$T/quickstart_offset.0000.exr" "$T/cpu_quickstart.0000.exr"
compare "offset rule with disc alpha (GPU) vs exact rule (CPU)" 0 "$T/quickstart_disc_offset.0000.exr" "$T/cpu_quickstart_disc.0000.exr"

# Every GPU layout against the CPU's exact frame (the CPU's image does not
# depend on the layout): layout_images' stems, then the CPU's overrides.
declare -A layouts=(
    [clusters_all]="" [instances]="" [aabbs]="" [aabbs_all]="" [clusters_threads4]=""
    [instances_disc]="${disc[*]}" [aabbs_disc]="${disc[*]}"
    [instances_omm4]="${disc[*]} -D gpu.omm=4state -D gpu.omm_level=4"
    [spheres]="-D geometry.primitive=sphere" [spheres_all]="-D geometry.primitive=sphere")
for name in clusters_all clusters_threads4 instances aabbs aabbs_all instances_disc aabbs_disc instances_omm4 spheres spheres_all; do
    [ -f "$T/$name.0000.exr" ] || continue
    # shellcheck disable=SC2086  # the overrides are words
    cpu "layout_$name" 0:1 -D render.estimator=exact ${layouts[$name]}
    compare "exact, layout $name" 0 "$T/$name.0000.exr" "$T/cpu_layout_$name.0000.exr"
done

# restir, frames 0-2: GPU stem, CPU stem, CPU overrides.
restir_case() {
    local gpu=$1 cpuStem=$2
    shift 2
    [ -f "$T/$gpu.0000.exr" ] || return 0
    [ -f "$T/cpu_$cpuStem.0000.exr" ] || cpu "$cpuStem" 0:3 -D render.estimator=restir "$@"
    for f in 0 1 2; do compare "restir $gpu" $f "$T/$gpu.000$f.exr" "$T/cpu_$cpuStem.000$f.exr"; done
}
for bc in none basic pairwise; do restir_case "$bc" "$bc" -D restir.bias_correction=$bc; done
restir_case basic_reorder basic
restir_case basic_scale0.5 basic_scale0.5 -D restir.resolution_scale=0.5
restir_case basic_scale0.75 basic_scale0.75 -D restir.resolution_scale=0.75
restir_case basic_omm4 basic_omm4 "${disc[@]}" -D gpu.omm=4state -D gpu.omm_level=4
restir_case basic_omm4_traverse basic_omm4
restir_case restir_power restir_power -D render.source=power
restir_case restir_tree restir_tree -D render.source=tree
# particle_restir (run.sh designs): the texels' reservoirs and the pixels read from them.
restir_case prt_interp prt_interp -D render.estimator=particle_restir -D restir.bias_correction=pairwise
restir_case prt_resample prt_resample -D render.estimator=particle_restir -D restir.bias_correction=pairwise -D restir.pixel_shading=resample
restir_case prt_2x2_k2 prt_2x2_k2 -D render.estimator=particle_restir -D restir.texels=2 -D restir.texel_rays=2
restir_case prt_history prt_history -D render.estimator=particle_restir -D restir.texel_rays=4 -D restir.texel_history=0.5 -D restir.spatial_neighbours=0
# voxel_cache (run.sh voxels: the cells and the pixels read from them) and
# particle_split (run.sh splits: the texels and the pixels), frames 0-2:
#   design_case ESTIMATOR GPU_STEM OVERRIDES...
design_case() {
    local estimator=$1 gpu=$2
    shift 2
    [ -f "$T/$gpu.0000.exr" ] || return 0
    cpu "$gpu" 0:3 -D render.estimator="$estimator" "$@"
    for f in 0 1 2; do compare "$estimator $gpu" $f "$T/$gpu.000$f.exr" "$T/cpu_$gpu.000$f.exr"; done
}
design_case voxel_cache vox_tree -D render.source=tree
design_case voxel_cache vox_power_camera -D render.source=power -D voxel.basis=camera
design_case voxel_cache vox_uniform_h1 -D render.source=uniform -D voxel.history=1 -D voxel.cells=16
design_case particle_split ps_n8_f4 -D particle_split.near=8 -D particle_split.far=4
design_case particle_split ps_2x2_c4_h5 -D particle_split.texels=2 -D particle_split.candidates=4 -D particle_split.history=0.5
design_case particle_split ps_n64_f0 -D particle_split.near=64 -D particle_split.far=0
# particle_split.texel_point jittered and antithetic (run.sh texel_point): the opaque square and the disc.
design_case particle_split ps_jit_c4_h5 -D particle_split.texel_point=jittered -D particle_split.candidates=4 -D particle_split.history=0.5
design_case particle_split ps_2x2_jit_disc_h5 -D particle_split.texel_point=jittered -D particle_split.texels=2 -D particle_split.history=0.5 "${disc[@]}"
design_case particle_split ps_2x2_anti_disc_h5 -D particle_split.texel_point=antithetic -D particle_split.texels=2 -D particle_split.history=0.5 "${disc[@]}"

# particle_split.history_start mean and history_of far (run.sh history_start).
design_case particle_split ps_mean_c4_h9 -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
design_case particle_split ps_mean_far_c4_h5 -D particle_split.history_start=mean -D particle_split.history_of=far -D particle_split.candidates=4 -D particle_split.history=0.5
design_case particle_split ps_2x2_far_anti_disc_h5 -D particle_split.history_of=far -D particle_split.texels=2 -D particle_split.texel_point=antithetic -D particle_split.history=0.5 "${disc[@]}"

# particle_split.far_new (run.sh far_new): a texel without history draws more far rays (frame 0: every texel).
design_case particle_split ps_new12_mean_c4_h9 -D particle_split.far_new=12 -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
design_case particle_split ps_new9_far_anti_h5 -D particle_split.far_new=9 -D particle_split.history_of=far -D particle_split.texel_point=antithetic -D particle_split.history=0.5
# particle_split.far_prior (run.sh far_prior): a new texel started from its near lights' far means.
design_case particle_split ps_prior8_mean_far_c4_h9 -D particle_split.far_prior=8 -D particle_split.history_of=far -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
# particle_split.far_share (run.sh far_share): every texel's far mean shown blended with its near lights'.
design_case particle_split ps_share24_prior8_mean_far_c4_h9 -D particle_split.far_share=24 -D particle_split.far_prior=8 -D particle_split.history_of=far -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
# particle_split.far_handoff (run.sh far_handoff).
design_case particle_split ps_handoff_share24_prior8_mean_far_c4_h9 -D particle_split.far_handoff=true -D particle_split.far_share=24 -D particle_split.far_prior=8 -D particle_split.history_of=far -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
design_case particle_split ps_handoff_2x2_far_anti_h5 -D particle_split.far_handoff=true -D particle_split.texels=2 -D particle_split.history_of=far -D particle_split.texel_point=antithetic -D particle_split.history=0.5

# uniform and power (one frame): Lr, its standard error and the samples taken.
declare -A sampled=(
    [power]="-D render.estimator=power -D render.samples=16"
    [uniform]="-D render.estimator=uniform -D render.samples=20"
    [power_adaptive]="-D render.estimator=power -D render.samples=8 -D render.target_stderr=0.05 -D render.max_samples=256"
    [power_disc]="-D render.estimator=power -D render.samples=16 ${disc[*]}")
for name in power uniform power_adaptive power_disc; do
    [ -f "$T/$name.0000.exr" ] || continue
    # shellcheck disable=SC2086  # the overrides are words
    cpu "$name" 0:1 ${sampled[$name]}
    compare "$name" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr"
    compare "$name Lr_stderr" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr" "--layer Lr_stderr"
    compare "$name spp" 0 "$T/$name.0000.exr" "$T/cpu_$name.0000.exr" "--layer spp"
done
column -s, -t "$csv"
