#!/bin/bash
# The OptiX twin's runs on a GPU machine, from the repository root:
#   bash bench/gpu/run.sh STEP...      steps: env build images restir sampling seeds sweep builds frame ncu
#                                      layout_images layouts streams front identity shared_core ab designs resample near_ncu voxel_ncu gather_ncu voxels splits iterations split_anatomy split_ncu split_stalls ray_launch split_order gbuffer_ncu near_cluster_ncu history texel_point history_start far_new far_prior far_share tune_h95 far_handoff
# Needs .twin-deps/ (made here by bench/gpu/stage_deps.sh on a Debian 12
# machine: the header-only and small libraries the twin's host code uses,
# the OptiX SDK headers, the commit). Results go to $OUT (or out/gpu).
set -uo pipefail
OUT=${OUT:-$PWD/out/gpu}
mkdir -p "$OUT"
D=$PWD/.twin-deps
S=$D/sysroot/usr
L=$S/lib/x86_64-linux-gnu
export LD_LIBRARY_PATH=$L${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
BIN=$PWD/build-gpu/accretion-optix
W=$OUT/work
mkdir -p "$W"

step_env() {
    { nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv; nvcc --version | tail -2
      g++ --version | head -1; cmake --version | head -1; nproc; cat "$D/commit"; } > "$OUT/env.txt" 2>&1
    cat "$OUT/env.txt"
}

# Configures and builds the twin of the source tree in $1 (build-gpu there),
# recording commit $2; the log goes to $3.
build_twin() {
    (cd "$1" && cmake -S . -B build-gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DACCRETION_CPU=OFF -DACCRETION_OPTIX=ON \
        -DOptiX_INCLUDE="$D/optix/include" -DACCRETION_COMMIT="$2" -DCMAKE_CUDA_ARCHITECTURES=90 \
        -DTBB_DIR=$L/cmake/TBB -Dfmt_DIR=$L/cmake/fmt -Dtomlplusplus_DIR=$L/cmake/tomlplusplus \
        -Dglm_DIR=$S/share/cmake/glm -Dnlohmann_json_DIR=$S/share/cmake/nlohmann_json -DCLI11_DIR=$S/share/cmake/CLI11 \
        > "$3" 2>&1 && cmake --build build-gpu -j 16 >> "$3" 2>&1)
}

step_build() {
    build_twin . "$(cat "$D/commit")" "$W/build.log"
    local rc=$?
    tail -30 "$W/build.log"
    return $rc
}

# GPU exact frames for the image-agreement checks (compared on the CPU machine).
step_images() {
    local q=scenes/quickstart.toml small="-D camera.width=320 -D camera.height=180 -D render.estimator=\"exact\""
    $BIN $q $small --frames 0:1 -o "$W/images/quickstart.{frame}.exr" --repeat 3
    $BIN $q $small --frames 0:1 -D geometry.alpha='"disc"' -o "$W/images/quickstart_disc.{frame}.exr" --repeat 3
    $BIN $q $small --frames 0:1 -D shading.model='"sphere"' -D geometry.orientation='"view_point"' \
        -o "$W/images/quickstart_sphere.{frame}.exr" --repeat 3
    timeout 300 $BIN scenes/disk_100k.toml $small --frames 0:1 \
        -o "$W/images/disk_100k.{frame}.exr" --repeat 1
    # Opacity micromaps: 4-state (the any-hit's image), 2-state (the CPU's
    # 2-state image), on primary and shadow rays; the offset visibility rule.
    local disc="-D geometry.alpha=disc"
    for m in 4state:2 4state:4 4state:6 2state:4; do
        $BIN $q $small $disc -D gpu.omm=${m%:*} -D gpu.omm_level=${m#*:} --frames 0:1 --repeat 3 \
            -o "$W/images/quickstart_omm${m%:*}_l${m#*:}.{frame}.exr"
    done
    $BIN $q $small -D render.visibility_rule=offset --frames 0:1 --repeat 3 -o "$W/images/quickstart_offset.{frame}.exr"
    $BIN $q $small $disc -D render.visibility_rule=offset --frames 0:1 --repeat 3 -o "$W/images/quickstart_disc_offset.{frame}.exr"
}

# GPU restir frames (quickstart, 320x180, 3 frames: temporal and spatial
# reuse), for the per-pixel comparison with the CPU's restir.
step_restir() {
    local q=scenes/quickstart.toml small="-D camera.width=320 -D camera.height=180 -D render.estimator=\"restir\""
    for bc in none basic pairwise; do
        $BIN $q $small --frames 0:3 -D restir.bias_correction=\"$bc\" -o "$W/restir/$bc.{frame}.exr" --repeat 3
    done
    $BIN $q $small --frames 0:3 -D restir.bias_correction=\"basic\" -o "$W/restir/basic_reorder.{frame}.exr" --repeat 3 \
        --shadow-rays reorder -D gpu.ser_hint_bits=8
    # Lighting at 0.5x and 0.75x with the upsampling pass; disc alpha with a
    # 4-state micromap on both shadow-ray paths.
    for sc in 0.5 0.75; do
        $BIN $q $small --frames 0:3 -D restir.resolution_scale=$sc -o "$W/restir/basic_scale$sc.{frame}.exr" --repeat 3
    done
    $BIN $q $small --frames 0:3 -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4 \
        -o "$W/restir/basic_omm4.{frame}.exr" --repeat 3
    $BIN $q $small --frames 0:3 -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4 --shadow-rays traverse \
        -o "$W/restir/basic_omm4_traverse.{frame}.exr" --repeat 3
}

# The Monte Carlo estimators (uniform, power: each chunk of 8 samples its own
# stream, as on the CPU; adaptive sampling by rounds) and restir's candidates
# drawn by power, for the per-pixel comparison with the CPU's frames; the
# GPU time of power at 64 spp on disk_100k.
step_sampling() {
    local q=scenes/quickstart.toml small="-D camera.width=320 -D camera.height=180"
    local t="$W/sampling"
    mkdir -p "$t"
    $BIN $q $small -D render.estimator=power -D render.samples=16 --frames 0:1 --repeat 3 -o "$t/power.{frame}.exr"
    $BIN $q $small -D render.estimator=uniform -D render.samples=20 --frames 0:1 --repeat 3 -o "$t/uniform.{frame}.exr"
    $BIN $q $small -D render.estimator=power -D render.samples=8 -D render.target_stderr=0.05 -D render.max_samples=256 \
        --frames 0:1 --repeat 3 -o "$t/power_adaptive.{frame}.exr"
    $BIN $q $small -D render.estimator=power -D render.samples=16 -D geometry.alpha=disc --frames 0:1 --repeat 3 \
        -o "$t/power_disc.{frame}.exr"
    $BIN $q $small -D render.estimator=restir -D render.source=power --frames 0:3 --repeat 3 -o "$t/restir_power.{frame}.exr"
    $BIN $q $small -D render.estimator=restir -D render.source=tree --frames 0:3 --repeat 3 -o "$t/restir_tree.{frame}.exr"
    $BIN scenes/disk_100k.toml --frames 0:1 --repeat 5 -o "$t/disk_100k_power64.{frame}.exr" \
        --timings "$t/disk_100k_power64.csv" --config power64
}

# restir over $SEEDS (64) seeds for `accretion bias --gpu-frames` (quickstart, 160x90,
# frame 2 after two history frames; Lr alone; one archive per estimator).
step_seeds() {
    local q=scenes/quickstart.toml
    for bc in none basic pairwise; do
        local t="$W/seeds_$bc"
        mkdir -p "$t"
        $BIN $q -D camera.width=160 -D camera.height=90 -D render.estimator=restir -D restir.bias_correction=$bc \
            --frames 0:3 --seeds "${SEEDS:-64}" --lr-only --repeat 1 -q -o "$t/restir_$bc.{frame}.exr" || return 1
        rm -f "$t"/*.0000.seed*.gpuframe "$t"/*.0001.seed*.gpuframe
        tar czf "$OUT/seeds_$bc.tar.gz" -C "$W" "seeds_$bc" && rm -rf "$t"
    done
}

# The cost-model sweep (bench/gpu/sweep.txt): per configuration the median
# GPU ms per pass of frame 1 (temporal reuse on), in cost's pass names.
# SWEEP_PART=i/n runs the i-th of n parts (1-based; the configurations in
# turn), so that a part fits one device call.
step_sweep() {
    local t="$W/sweep" part=${SWEEP_PART:-1/1} k=0
    mkdir -p "$t"
    grep -v '^#' "${SWEEP_LIST:-bench/gpu/sweep.txt}" | while read -r name args; do
        [ -z "$name" ] && continue
        k=$((k + 1))
        [ $(((k - 1) % ${part#*/})) -eq $((${part%/*} - 1)) ] || continue
        # shellcheck disable=SC2086  # the overrides are words
        timeout 150 $BIN scenes/disk_100k.toml -D render.estimator=restir $args --frames 0:2 --repeat 5 -q \
            -o "$t/$name.{frame}.exr" --timings "$t/$name.timings.csv" --config "$name" < /dev/null \
            || echo "sweep: $name failed"
        rm -f "$t"/*.gpuframe
        echo "sweep: $name done"
    done
    { echo config,pass,ms; for f in "$t"/*.timings.csv; do tail -n +2 "$f"; done; } > "$t/timings_${part%/*}.csv"
}

# The build questions of the team's original design: rebuild / refit / partial, pooled / per-BLAS,
# compaction, cluster size 100 / 1000, at 100K particles and 1080p.
step_builds() {
    local s=scenes/disk_100k.toml f="-D camera.width=1920 -D camera.height=1080 --skip-lighting --repeat 7"
    local t="$W/builds"
    mkdir -p "$t"
    run() { local name=$1; shift; $BIN $s $f -o "$t/$name.{frame}.exr" --timings "$t/$name.csv" --config "$name" "$@"; }
    run rebuild_k100 --frames 0:2
    run rebuild_k1000 --frames 0:2 -D geometry.cluster_size=1000
    run rebuild_k100_perblas --frames 0:2 --per-blas
    run rebuild_k100_compact --frames 0:2 --compact
    run fasttrace_k100 --frames 0:2 -D geometry.build='"fast_trace"'
    run refit_k100 --frames 0:6 -D geometry.build='"refit"'
    run partial_k100 --frames 0:6 -D geometry.build='"partial"'
    run rebuild_k25 --frames 0:2 -D geometry.cluster_size=25
    run rebuild_k1600 --frames 0:2 -D geometry.cluster_size=1600
    run rebuild_k100_streams4 --frames 0:2 --build-streams 4
    run rebuild_k100_streams16 --frames 0:2 --build-streams 16
    run rebuild_k25_streams16 --frames 0:2 -D geometry.cluster_size=25 --build-streams 16
    run refit_k100_streams16 --frames 0:6 -D geometry.build='"refit"' --build-streams 16
    rm -f "$t"/*.gpuframe
}

# The original design's frame: 100K particles, restir at 1080p, per-pass GPU ms: the
# three shadow-ray paths, cluster sizes 100 and 1000, lighting at 0.75x and
# 0.5x (restir.resolution_scale, with the upsampling pass), disc alpha by
# any-hit and by 4- and 2-state micromaps.
step_frame() {
    local s=scenes/disk_100k.toml r="-D render.estimator=restir --frames 0:3 --repeat 7 -D camera.width=1920 -D camera.height=1080"
    local t="$W/frame"
    mkdir -p "$t"
    # shellcheck disable=SC2086  # $r holds words
    run() { local name=$1; shift; $BIN $s $r -o "$t/$name.{frame}.exr" --timings "$t/$name.csv" --config "$name" "$@"; }
    run k100_trace
    run k100_traverse --shadow-rays traverse
    run k100_reorder --shadow-rays reorder -D gpu.ser_hint_bits=8
    run k1000_trace -D geometry.cluster_size=1000
    run k100_trace_scale075 -D restir.resolution_scale=0.75
    run k100_trace_scale050 -D restir.resolution_scale=0.5
    run k100_anyhit -D geometry.alpha=disc
    run k100_omm4_l4 -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4
    run k100_omm2_l4 -D geometry.alpha=disc -D gpu.omm=2state -D gpu.omm_level=4
    run k100_anyhit_traverse -D geometry.alpha=disc --shadow-rays traverse
    run k100_omm4_l4_traverse -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4 --shadow-rays traverse
    # Under the offset rule (what GPU code does) no ray is traced again past its own billboard.
    run k100_anyhit_offset -D geometry.alpha=disc -D render.visibility_rule=offset
    run k100_omm4_l4_offset -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4 -D render.visibility_rule=offset
    rm -f "$t"/*.gpuframe
}

# Every layout's exact frame (quickstart, 320x180), for the per-pixel
# comparison with the CPU: the layout changes the traversal, not the image.
step_layout_images() {
    local q=scenes/quickstart.toml small="-D camera.width=320 -D camera.height=180 -D render.estimator=exact"
    local t="$W/layout_images"
    mkdir -p "$t"
    one() { local name=$1; shift; $BIN $q $small --frames 0:1 --repeat 1 -q -o "$t/$name.{frame}.exr" "$@" || echo "layout_images: $name failed"; }
    one clusters_all -D geometry.cluster_size=10000000
    one instances -D geometry.layout=instances
    one aabbs -D geometry.layout=aabbs
    one aabbs_all -D geometry.layout=aabbs -D geometry.cluster_size=10000000
    one instances_disc -D geometry.layout=instances -D geometry.alpha=disc
    one aabbs_disc -D geometry.layout=aabbs -D geometry.alpha=disc
    one instances_omm4 -D geometry.layout=instances -D geometry.alpha=disc -D gpu.omm=4state -D gpu.omm_level=4
    one spheres -D geometry.primitive=sphere
    one spheres_all -D geometry.primitive=sphere -D geometry.cluster_size=10000000
    one clusters_threads4 --build-threads 4
}

# The layout decision matrix (bench/gpu/layouts.txt): every layout at 10K,
# 100K and 1M particles, 720p and 1080p, restir (frame 1 after a history
# frame), per-pass GPU ms (`accretion-optix --timings`) and the acceleration
# structure's memory (the stats JSON). LAYOUT_PARTS=i/n runs the i-th of n parts;
# LAYOUT_LIST another list (bench/gpu/layouts_refit.txt); REPEAT the timed runs
# per frame (3; a pass's time is their median).
# Times the "name -D overrides..." lines of list $2 (comments and blank lines
# skipped), each on disk_100k's (or scene $5's) restir frame 1 after a history
# frame, $3 timed runs per frame, into $W/$1; with parts i/n ($4), the i-th of n parts.
time_configs() {
    local t="$W/$1" list=$2 repeat=$3 part=${4:-1/1} scene=${5:-scenes/disk_100k.toml} k=0
    mkdir -p "$t"
    grep -v '^#' "$list" | sed 's/ *#.*//' | while read -r name args; do
        [ -z "$name" ] && continue
        k=$((k + 1))
        [ $(((k - 1) % ${part#*/})) -eq $((${part%/*} - 1)) ] || continue
        # shellcheck disable=SC2086  # the overrides are words
        timeout 120 $BIN "$scene" -D render.estimator=restir $args --frames 0:2 --repeat "$repeat" -q \
            -o "$t/$name.{frame}.exr" --timings "$t/$name.timings.csv" --config "$name" < /dev/null \
            || echo "$1: $name failed"
        rm -f "$t"/*.gpuframe
    done
}

step_layouts() { time_configs layouts "${LAYOUT_LIST:-bench/gpu/layouts.txt}" "${REPEAT:-3}" "${LAYOUT_PARTS:-1/1}"; }

# The per-launch costs of many small builds: clusters of 25, 100 and 1000 at
# 100K and 1M particles, 1080p, with the builds spread over 4 and 16 streams
# from one host thread, or issued from 4 host threads (each its own stream).
step_streams() {
    local t="$W/streams"
    mkdir -p "$t"
    for p in 100000 1000000; do
        for k in 25 100 1000; do
            for v in streams4:"--build-streams 4" streams16:"--build-streams 16" threads4:"--build-threads 4"; do
                local n=p${p}_1920x1080_k${k}_${v%%:*}
                # shellcheck disable=SC2086  # the flags are words
                timeout 120 $BIN scenes/disk_100k.toml -D render.estimator=restir -D particles.count=$p \
                    -D camera.width=1920 -D camera.height=1080 -D geometry.cluster_size=$k ${v#*:} --frames 0:2 \
                    --repeat 3 -q -o "$t/$n.{frame}.exr" --timings "$t/$n.timings.csv" --config "$n" < /dev/null \
                    || echo "streams: $n failed"
                rm -f "$t"/*.gpuframe
            done
        done
    done
}

# The designs of issue 46 (bench/gpu/designs.txt: restir per pixel and
# particle_restir per particle texel at 100K and 1M, 1080p), timed as the
# layouts are (frame 1 after a history frame, 5 timed runs); and
# particle_restir's frames on quickstart at 320x180 (frames 0-2) for the
# per-pixel comparison with the CPU (compare_cpu.sh).
# Frames 0-2 of quickstart at 320x180 into $W/STEP/images/NAME.{frame}
# (compare_cpu.sh renders the CPU's beside them):
#   quickstart_frames STEP ESTIMATOR NAME OVERRIDES...
quickstart_frames() {
    local step=$1 estimator=$2 name=$3
    shift 3
    mkdir -p "$W/$step/images"
    $BIN scenes/quickstart.toml -D camera.width=320 -D camera.height=180 -D render.estimator="$estimator" "$@" --frames 0:3 \
        --repeat 1 -q -o "$W/$step/images/$name.{frame}.exr" || echo "$step: $name failed"
}

step_designs() {
    quickstart_frames designs particle_restir prt_interp -D restir.bias_correction=pairwise
    quickstart_frames designs particle_restir prt_resample -D restir.bias_correction=pairwise -D restir.pixel_shading=resample
    quickstart_frames designs particle_restir prt_2x2_k2 -D restir.texels=2 -D restir.texel_rays=2
    quickstart_frames designs particle_restir prt_history -D restir.texel_rays=4 -D restir.texel_history=0.5 -D restir.spatial_neighbours=0
    time_configs designs bench/gpu/designs.txt 5
    # The flattened cluster from raw buffers (made here: they are not committed).
    python3 scenes/cluster/make_cluster.py 3
    time_configs designs/cluster bench/gpu/designs_cluster.txt 5 1/1 scenes/cluster_150k.toml
}

# particle_restir's resample variant, resampleParticlePixels since aaf54f8
# (it had been timed as shadeParticlePixels): designs.txt's and
# designs_cluster.txt's prt_*_resample lines timed again, beside the
# interpolating prt_m8_k4 at 100K and on the cluster timed in the same run.
step_resample() {
    grep -E '^prt_[a-z0-9_]*resample_(100k|1m) |^prt_m8_k4_100k ' bench/gpu/designs.txt > "$W/resample.txt"
    time_configs resample "$W/resample.txt" 5
    python3 scenes/cluster/make_cluster.py 3
    grep -E '^prt_m8_k4(_resample)?_cluster ' bench/gpu/designs_cluster.txt > "$W/resample_cluster.txt"
    time_configs resample/cluster "$W/resample_cluster.txt" 5 1/1 scenes/cluster_150k.toml
}

# seed 004's voxel radiance cache (designs.txt's vox_ lines, 100K and 1M at
# 1080p, and designs_cluster.txt's on cluster_150k), timed as the designs are, beside today's recommendations and
# particle_restir's best timed again in the same run; and its frames on
# quickstart at 320x180 (frames 0-2) for the per-pixel comparison with the
# CPU (compare_cpu.sh).
step_voxels() {
    quickstart_frames voxels voxel_cache vox_tree -D render.source=tree
    quickstart_frames voxels voxel_cache vox_power_camera -D render.source=power -D voxel.basis=camera
    quickstart_frames voxels voxel_cache vox_uniform_h1 -D render.source=uniform -D voxel.history=1 -D voxel.cells=16
    grep -E '^(vox_[a-z0-9_]*|restir_m32_t_basic_1x_100k|restir_m32_t_pairwise_05x_1m|prt_m8_k16_100k|prt_m8_k4_1m) ' bench/gpu/designs.txt > "$W/voxels.txt"
    time_configs voxels "$W/voxels.txt" 5
    # And on the flattened cluster (designs_cluster.txt's vox_ lines).
    python3 scenes/cluster/make_cluster.py 3
    grep -E '^vox_[a-z0-9_]* ' bench/gpu/designs_cluster.txt > "$W/voxels_cluster.txt"
    time_configs voxels/cluster "$W/voxels_cluster.txt" 5 1/1 scenes/cluster_150k.toml
}

# seed 004's hybrid compute, particle_split (designs.txt's ps_ lines, 100K
# and 1M at 1080p, and designs_cluster.txt's), timed as the designs are,
# beside today's recommendations and particle_restir's best timed again in
# the same run; and its frames on quickstart at 320x180 (frames 0-2) for
# the per-pixel comparison with the CPU (compare_cpu.sh).
step_splits() {
    quickstart_frames splits particle_split ps_n8_f4 -D particle_split.near=8 -D particle_split.far=4
    quickstart_frames splits particle_split ps_2x2_c4_h5 -D particle_split.texels=2 -D particle_split.candidates=4 -D particle_split.history=0.5
    quickstart_frames splits particle_split ps_n64_f0 -D particle_split.near=64 -D particle_split.far=0
    grep -E '^(ps_[a-z0-9_]*|restir_m32_t_basic_1x_100k|restir_m32_t_pairwise_05x_1m|prt_m8_k16_100k|prt_m8_k4_1m) ' bench/gpu/designs.txt > "$W/splits.txt"
    time_configs splits "$W/splits.txt" 5
    python3 scenes/cluster/make_cluster.py 3
    grep -E '^(ps_[a-z0-9_]*|restir_m32_t_basic_1x_cluster|prt_m8_k16_cluster) ' bench/gpu/designs_cluster.txt > "$W/splits_cluster.txt"
    time_configs splits/cluster "$W/splits_cluster.txt" 5 1/1 scenes/cluster_150k.toml
}

# The texel history's weight (particle_split.history: 0.75, 0.875, 0.9), a
# scalar of the same kernels, timed side by side with today's
# recommendations (restir M=32 at 0.5x and at 1x) on one GPU in one run.
step_history() {
    grep -E '^(ps_n8_f4_c8_h(75|875|90)_100k|ps_n16_f8_c8_h75_100k|ps_n8_f4_c4_h(75|90)_1m|restir_m32_t_pairwise_05x_(100k|1m)|restir_m32_t_basic_1x_100k) ' \
        bench/gpu/designs.txt > "$W/history.txt"
    time_configs history "$W/history.txt" 5
}

# particle_split.texel_point jittered and antithetic (a texel's receiver
# drawn afresh each frame in its square, or mirrored every other frame):
# their frames on quickstart at 320x180 (frames 0-2) for the per-pixel
# comparison with the CPU (compare_cpu.sh), in the opaque square and in the
# disc; and designs.txt's _jit_ and _anti_ lines timed beside the same
# configurations at their centres and today's recommendations, in one run.
step_texel_point() {
    quickstart_frames texel_point particle_split ps_jit_c4_h5 -D particle_split.texel_point=jittered -D particle_split.candidates=4 \
        -D particle_split.history=0.5
    quickstart_frames texel_point particle_split ps_2x2_jit_disc_h5 -D particle_split.texel_point=jittered -D particle_split.texels=2 \
        -D particle_split.history=0.5 -D geometry.alpha=disc
    quickstart_frames texel_point particle_split ps_2x2_anti_disc_h5 -D particle_split.texel_point=antithetic -D particle_split.texels=2 \
        -D particle_split.history=0.5 -D geometry.alpha=disc
    grep -E '^(ps_n8_f4_c8_h(75|90)(_jit|_anti)?_100k|ps_n16_f8_c8_h90(_jit|_anti)?_100k|ps_n8_f4_c4_h(75|90)(_jit|_anti)?_1m|restir_m32_t_pairwise_05x_(100k|1m)) ' \
        bench/gpu/designs.txt > "$W/texel_point.txt"
    time_configs texel_point "$W/texel_point.txt" 5
}

# particle_split.history_start mean (a texel's running mean over its first
# frames) and history_of far (the far mean's history alone): their frames on
# quickstart at 320x180 (frames 0-2) for the per-pixel comparison with the
# CPU (compare_cpu.sh), and designs.txt's _mean lines timed beside the same
# configurations without them and today's recommendations, in one run.
step_history_start() {
    quickstart_frames history_start particle_split ps_mean_c4_h9 -D particle_split.history_start=mean -D particle_split.candidates=4 \
        -D particle_split.history=0.9
    quickstart_frames history_start particle_split ps_mean_far_c4_h5 -D particle_split.history_start=mean -D particle_split.history_of=far \
        -D particle_split.candidates=4 -D particle_split.history=0.5
    quickstart_frames history_start particle_split ps_2x2_far_anti_disc_h5 -D particle_split.history_of=far -D particle_split.texels=2 \
        -D particle_split.texel_point=antithetic -D particle_split.history=0.5 -D geometry.alpha=disc
    grep -E '^(ps_n8_f4_c8_h90(_mean|_mean_far)?_100k|ps_n8_f4_c8_h95_mean_far_100k|ps_n8_f4_c4_h90_anti(_mean)?_1m|ps_n8_f4_c4_h95_(anti_mean|anti_mean_far|mean_far)_1m|restir_m32_t_pairwise_05x_(100k|1m)) ' \
        bench/gpu/designs.txt > "$W/history_start.txt"
    time_configs history_start "$W/history_start.txt" 5
}

# particle_split.far_new (more far rays for a texel without history: a
# select of those texels, then their extra rays in the same launch): its
# frames on quickstart at 320x180 (frames 0-2) for the per-pixel comparison
# with the CPU (compare_cpu.sh), and designs.txt's _new lines timed beside
# the same configurations without it and today's recommendations, in one run.
step_far_new() {
    quickstart_frames far_new particle_split ps_new12_mean_c4_h9 -D particle_split.far_new=12 -D particle_split.history_start=mean \
        -D particle_split.candidates=4 -D particle_split.history=0.9
    quickstart_frames far_new particle_split ps_new9_far_anti_h5 -D particle_split.far_new=9 -D particle_split.history_of=far \
        -D particle_split.texel_point=antithetic -D particle_split.history=0.5
    grep -E '^(ps_n8_f4_c8_h95_mean_far(_new16)?_100k|ps_n8_f4_c4_h95_anti_mean_far(_new(8|16|32))?_1m|restir_m32_t_pairwise_05x_(100k|1m)) ' \
        bench/gpu/designs.txt > "$W/far_new.txt"
    time_configs far_new "$W/far_new.txt" 5
}

# particle_split.far_prior (a texel without history started from its near
# lights' far means of last frame): its frames on quickstart (frames 0-2,
# the disk rotating particles into view) for compare_cpu.sh, and
# designs.txt's _prior lines timed beside the same configurations without
# it, far_new 8 and today's recommendations, in one run.
step_far_prior() {
    quickstart_frames far_prior particle_split ps_prior8_mean_far_c4_h9 -D particle_split.far_prior=8 -D particle_split.history_of=far \
        -D particle_split.history_start=mean -D particle_split.candidates=4 -D particle_split.history=0.9
    grep -E '^(ps_n8_f4_c8_h95_mean_far(_prior32)?_100k|ps_n8_f4_c4_h95_anti_mean_far(_new8|_prior8|_prior32|_new8_prior32)?_1m|restir_m32_t_pairwise_05x_(100k|1m)) ' \
        bench/gpu/designs.txt > "$W/far_prior.txt"
    time_configs far_prior "$W/far_prior.txt" 5
}

# particle_split.far_share (every texel's far mean shown blended with its
# near lights' of last frame): its frames on quickstart for compare_cpu.sh,
# and designs.txt's _share lines timed beside the same configurations
# without it and today's recommendations, in one run.
step_far_share() {
    quickstart_frames far_share particle_split ps_share24_prior8_mean_far_c4_h9 -D particle_split.far_share=24 \
        -D particle_split.far_prior=8 -D particle_split.history_of=far -D particle_split.history_start=mean \
        -D particle_split.candidates=4 -D particle_split.history=0.9
    grep -E '^(ps_n8_f4_c8_h95_mean_far_prior32(_share(64|256))?_100k|ps_n8_f4_c4_h95_anti_mean_far_prior32(_share(64|256))?_1m|restir_m32_t_pairwise_05x_(100k|1m)) ' \
        bench/gpu/designs.txt > "$W/far_share.txt"
    time_configs far_share "$W/far_share.txt" 5
}

# tune's quick space at h = 0.95 (its five particle_split configurations
# with the long history, cmd_tune.cpp) at 100K, beside its earlier
# recommendation (near 16, far 16 of 8, h = 0.75) and restir's best, in one
# run: the twin's times of what tune priced with the cost model.
step_tune_h95() {
    grep -E '^(ps_n8_f4_c8_h95_mean_far(_prior32_share(64|256))?|ps_n8_f4_c4_h95_anti_mean_far_prior32_share256|ps_n16_f8_c8_h95_mean_far_prior32_share256|ps_n16_f16_c8_h75|restir_m32_t_pairwise_05x)_100k ' \
        bench/gpu/designs.txt > "$W/tune_h95.txt"
    time_configs tune_h95 "$W/tune_h95.txt" 5
}

# particle_split.far_handoff (the far history follows the near set): its
# frames on quickstart (frames 0-2, the disk rotating particles' near sets
# apart) for compare_cpu.sh, and designs.txt's _handoff lines timed beside
# the same configurations without it, in one run.
step_far_handoff() {
    quickstart_frames far_handoff particle_split ps_handoff_share24_prior8_mean_far_c4_h9 -D particle_split.far_handoff=true \
        -D particle_split.far_share=24 -D particle_split.far_prior=8 -D particle_split.history_of=far -D particle_split.history_start=mean \
        -D particle_split.candidates=4 -D particle_split.history=0.9
    quickstart_frames far_handoff particle_split ps_handoff_2x2_far_anti_h5 -D particle_split.far_handoff=true -D particle_split.texels=2 \
        -D particle_split.history_of=far -D particle_split.texel_point=antithetic -D particle_split.history=0.5
    grep -E '^(ps_n8_f4_c8_h95_mean_far_prior32_share256(_handoff)?_100k|ps_n16_f8_c8_h95_mean_far(_prior32_share256)?(_handoff)?_100k|ps_n8_f4_c4_h95_anti_mean_far_prior32_share256(_handoff)?_1m) ' \
        bench/gpu/designs.txt > "$W/far_handoff.txt"
    time_configs far_handoff "$W/far_handoff.txt" 5
}

# The spatial passes run once and twice, each iteration timed apart
# ("spatialResampling[2]", "resampleWorldNeighbours[2]"): designs.txt's and
# designs_cluster.txt's restir lines of 5 and 10 neighbours and
# particle_restir's world neighbours (at 1M too), for the cost model's
# held-out check of the iterated passes (designs_fit.sh).
step_iterations() {
    local pick='^(restir_m8_nb[0-9]+(x2)?_[a-z]+_[0-9x]+|prt_m8_k4_world5(x2)?)_'
    grep -E "${pick}(100k|1m) " bench/gpu/designs.txt > "$W/iterations.txt"
    time_configs iterations "$W/iterations.txt" 5
    python3 scenes/cluster/make_cluster.py 3
    grep -E "${pick}cluster " bench/gpu/designs_cluster.txt > "$W/iterations_cluster.txt"
    time_configs iterations/cluster "$W/iterations_cluster.txt" 5 1/1 scenes/cluster_150k.toml
}

# particle_split's shadeSplitTexels taken apart (bench/gpu/split_anatomy.txt):
# the near lights' count against the far rays' cost, with and without RIS
# and shadow rays.
step_split_anatomy() { time_configs split_anatomy bench/gpu/split_anatomy.txt 5; }

# Nsight Compute of configuration N of LIST (its line "N overrides...") on
# disk_100k (or SCENE), frames 0-1, its OptiX launches only (or the kernels KERNEL, a
# regex, matches): `ncu ARGS` (and --metrics
# M where M is not empty) logged to FOLDER/STEM.log, the run's output to
# STEM.run.log; then each of PAGES (raw, details) imported as CSV, with
# --metrics M: STEM.csv where PAGES is one page, else STEM.PAGE.csv. The
# report and the frames are removed.
#   ncu_config FOLDER STEM LIST N "ARGS" M "PAGES" [KERNEL] [SCENE]
ncu_config() {
    local t=$1 stem=$2 list=$3 n=$4 args=$5 m=$6 pages=$7 kernel=${8:-optixLaunch} scene=${9:-scenes/disk_100k.toml} p csv sel=()
    [ -z "$m" ] || sel=(--metrics "$m")
    # shellcheck disable=SC2046,SC2086  # the ncu arguments and the overrides are words
    timeout 240 ncu $args "${sel[@]}" --kernel-name regex:"$kernel" --log-file "$t/$stem.log" -o "$t/$stem" \
        $BIN "$scene" $(grep "^$n " "$list" | sed 's/ *#.*//' | cut -d' ' -f2-) \
        --frames 0:2 --repeat 1 -q -o "$t/$stem.{frame}.exr" > "$t/$stem.run.log" 2>&1
    for p in $pages; do
        csv="$t/$stem.$p.csv"
        [ "$p" != "$pages" ] || csv="$t/$stem.csv"
        ncu --import "$t/$stem.ncu-rep" --csv --page "$p" "${sel[@]}" > "$csv" 2>&1
    done
    rm -f "$t"/*.gpuframe "$t"/*.exr "$t/$stem.ncu-rep"
}

# The near search's memory at 100K and 1M (designs.txt's ps_n8_f4_c8_h75_*):
# findNearLightsKernel's time, its L1 and L2 hit rates and the bytes it
# reads from DRAM, under Nsight Compute; whether 1M's 32 MB of light
# records still fit the GPU's L2 (docs/designs.md, tune at 1M).
step_near_ncu() {
    local t="$W/near_ncu" m=gpu__time_duration.sum,lts__t_sector_hit_rate.pct,l1tex__t_sector_hit_rate.pct,dram__bytes_read.sum,lts__t_bytes.sum n
    mkdir -p "$t"
    for n in ps_n8_f4_c8_h75_100k ps_n8_f4_c8_h75_1m; do ncu_config "$t" "$n" bench/gpu/designs.txt "$n" "" "$m" raw findNearLightsKernel; done
}

# Why the cluster's near search costs more per counted step than the
# disk's (docs/designs.md, node visits: findNearLights -43% on the cluster
# in the fit of every configuration): findNearLightsKernel of
# ps_n8_f4_c8_h75 at 100K and on cluster_150k, its time, warp instructions,
# SIMT efficiency, L1 and L2 hit rates and DRAM bytes under Nsight Compute.
step_near_cluster_ncu() {
    local t="$W/near_cluster_ncu" m=gpu__time_duration.sum,smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio
    m=$m,lts__t_sector_hit_rate.pct,l1tex__t_sector_hit_rate.pct,dram__bytes_read.sum,smsp__average_warp_latency_per_inst_issued.ratio
    mkdir -p "$t"
    ncu_config "$t" ps_n8_f4_c8_h75_100k bench/gpu/designs.txt ps_n8_f4_c8_h75_100k "" "$m" raw findNearLightsKernel
    python3 scenes/cluster/make_cluster.py 3
    ncu_config "$t" ps_n8_f4_c8_h75_cluster bench/gpu/designs_cluster.txt ps_n8_f4_c8_h75_cluster "" "$m" raw \
        findNearLightsKernel scenes/cluster_150k.toml
}

# updateVoxelCache's three kernels at 100K and 1M (designs.txt's
# vox_c32_r8_*, or the configurations VOXEL_NCU names): the cells marked (a
# thread per particle), the cells' rays (an OptiX launch) and their sums,
# each kernel's time under Nsight Compute.
step_voxel_ncu() {
    local t="$W/voxel_ncu" n
    mkdir -p "$t"
    for n in ${VOXEL_NCU:-vox_c32_r8_100k vox_c32_r8_1m}; do
        ncu_config "$t" "$n" bench/gpu/designs.txt "$n" "" gpu__time_duration.sum raw 'markVoxelCells|sumVoxelRays|optixLaunch'
    done
}

# gatherParticleTexels' kernels at 100K and 1M (designs.txt's
# prt_m8_k4_*): the visible flags (a thread per pixel), the ids, CUB's
# select and radix sort, the Morton keys, the slots and the texels, each
# kernel's time and launch size under Nsight Compute: what the pass's
# item_steps count (docs/cost-model.md).
step_gather_ncu() {
    local t="$W/gather_ncu" n
    mkdir -p "$t"
    for n in prt_m8_k4_100k prt_m8_k4_1m; do
        ncu_config "$t" "$n" bench/gpu/designs.txt "$n" "" gpu__time_duration.sum,launch__grid_size,launch__block_size raw \
            'markVisible|iotaKernel|mortonKeys|writeSlots|writeTexels|Select|Radix|Onesweep|Scan'
    done
}

# The traversal model's check (node_visits, docs/designs.md): Nsight Compute
# of the G-buffer launch at 100K, 1M and on cluster_150k (the camera and
# geometry of restir_m8_t_pairwise_1x_*, whose lines name no estimator: the
# twin's default, power, lights them, so launches 0 and 2 are frames 0 and
# 1's G-buffer, 1 and 3 the power estimator's): time, warp instructions and
# SIMT efficiency. The H100 and H200 traverse in software, so a launch's
# warp instructions follow its warps' traversal loops.
step_gbuffer_ncu() {
    local t="$W/gbuffer_ncu" m=gpu__time_duration.sum,smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio n
    mkdir -p "$t"
    for n in restir_m8_t_pairwise_1x_100k restir_m8_t_pairwise_1x_1m; do ncu_config "$t" "$n" bench/gpu/designs.txt "$n" "" "$m" raw; done
    python3 scenes/cluster/make_cluster.py 3
    ncu_config "$t" restir_m8_t_pairwise_1x_cluster bench/gpu/designs_cluster.txt restir_m8_t_pairwise_1x_cluster "" "$m" raw \
        optixLaunch scenes/cluster_150k.toml
}

# Nsight Compute of particle_split's ray launch (shadeSplitTexels) at 8 and
# 16 near lights (far 4 of 8; split_anatomy.txt's sa_n8_f4_c8 and
# sa_n16_f4_c8): time, instructions, SIMT efficiency, local and device
# memory traffic of each OptiX launch of frame 1.
step_split_ncu() {
    local t="$W/split_ncu" m=gpu__time_duration.sum,smsp__inst_executed.sum,smsp__thread_inst_executed_per_inst_executed.ratio n
    m=$m,l1tex__t_bytes_pipe_lsu_mem_local_op_ld.sum,l1tex__t_bytes_pipe_lsu_mem_local_op_st.sum,dram__bytes_read.sum,lts__t_bytes.sum
    mkdir -p "$t"
    for n in sa_n8_f4_c8 sa_n16_f4_c8; do ncu_config "$t" "$n" bench/gpu/split_anatomy.txt "$n" "" "$m" raw; done
}

# Why particle_split's ray launch costs more at 8 near lights than at 16
# (split_ncu: fewer instructions in more time): Nsight Compute's warp-state
# (stall reasons), scheduler, occupancy, memory and instruction sections of
# frame 1's shadeSplitTexels launch (the 4th optixLaunch of frames 0-1), at
# 8 and 16 near lights with and without shadow rays.
step_split_stalls() {
    local t="$W/split_stalls" s n
    mkdir -p "$t"
    s="--section SpeedOfLight --section LaunchStats --section Occupancy --section WarpStateStats --section SchedulerStats"
    s="$s --section MemoryWorkloadAnalysis --section InstructionStats --section ComputeWorkloadAnalysis --section SourceCounters"
    for n in sa_n8_f4_c8 sa_n16_f4_c8 sa_n8_f4_c8_novis sa_n16_f4_c8_novis; do
        ncu_config "$t" "$n" bench/gpu/split_anatomy.txt "$n" "$s --launch-skip 3 --launch-count 1" "" "details raw"
    done
}

# Whether variants A and B of configuration N of LIST (its lines "N_A ..."
# and "N_B ...") render frames 0 and 1 of disk_100k the same, byte for byte
# (frame 1: with history); a line a frame.
#   same_frames FOLDER LIST N A B
same_frames() {
    local t=$1 list=$2 n=$3 a=$4 b=$5 v f
    for v in "$a" "$b"; do
        # shellcheck disable=SC2046  # the overrides are words
        $BIN scenes/disk_100k.toml $(grep "^${n}_$v " "$list" | cut -d' ' -f2-) --frames 0:2 --repeat 1 -q -o "$t/same_${n}_$v.{frame}.exr"
    done
    for f in 0000 0001; do
        python3 bench/gpu/gpuframe_equal.py "$t/same_${n}_$a.$f.gpuframe" "$t/same_${n}_$b.$f.gpuframe" &&
            echo "$n frame $f: the same with $a and $b" || echo "$n frame $f: DIFFERS"
    done
    rm -f "$t"/same_*.gpuframe
}

# The launches of a thread per ray (particle_split's shadeSplitTexels,
# voxel_cache's updateVoxelCache) as rows (OptiX's 2D launch) against one
# row (twin --ray-launch): split_anatomy's configurations and designs.txt's
# 100K voxel ones timed both ways; at 8 and 16 near lights the warps'
# barrier and memory stalls, occupancy and time of frame 1's split launch;
# the frames of both, byte for byte.
step_ray_launch() {
    local t="$W/ray_launch" list="$W/ray_launch.txt" n m
    mkdir -p "$t"
    { grep '^sa_' bench/gpu/split_anatomy.txt; grep -E '^vox_[a-z0-9_]*_100k ' bench/gpu/designs.txt; } | sed 's/ *#.*//' |
        awk '{n = $1; $1 = ""; print n "_rows" $0 " --ray-launch rows"; print n "_linear" $0 " --ray-launch linear"}' > "$list"
    time_configs ray_launch "$list" 5
    m=gpu__time_duration.sum,smsp__inst_executed.sum,sm__warps_active.avg.pct_of_peak_sustained_active
    m=$m,smsp__average_warps_issue_stalled_barrier_per_issue_active.ratio,smsp__average_warps_issue_stalled_long_scoreboard_per_issue_active.ratio
    m=$m,smsp__average_warps_issue_stalled_wait_per_issue_active.ratio,smsp__thread_inst_executed_per_inst_executed.ratio
    for n in sa_n8_f4_c8_rows sa_n16_f4_c8_rows sa_n8_f4_c8_linear sa_n16_f4_c8_linear; do
        ncu_config "$t" "$n.ncu" "$list" "$n" "--launch-skip 3 --launch-count 1" "$m" raw
    done
    { same_frames "$t" "$list" sa_n8_f4_c8 rows linear; same_frames "$t" "$list" vox_c64_r8_100k rows linear; } | tee "$t/same.txt"
}

# particle_split's ray threads in three orders (twin --ray-launch): rows
# (OptiX's 2D launch), linear (a ray of every texel, then the next) and
# texels (the near rays texel by texel, then the far ones): designs.txt's
# 100K particle_split configurations; the frames of texels and linear
# compared byte for byte.
step_split_order() {
    # texels is the default (particle_split_passes.h: splitRayThread).
    local t="$W/split_order" list="$W/split_order.txt"
    mkdir -p "$t"
    grep -E '^ps_[a-z0-9_]*_100k ' bench/gpu/designs.txt | sed 's/ *#.*//' |
        awk '{n = $1; $1 = ""; for (v = 1; v <= 3; ++v) { o = v == 1 ? "rows" : v == 2 ? "linear" : "texels"; print n "_" o $0 " --ray-launch " o } }' > "$list"
    time_configs split_order "$list" 5
    same_frames "$t" "$list" ps_n16_f8_c8_h75_100k linear texels | tee "$t/same.txt"
}

# The configurations on tune's Pareto fronts (bench/gpu/front.txt, written
# by bench/gpu/front_configs.py), timed as the layouts are.
step_front() { time_configs front bench/gpu/front.txt 5; }

# Nsight Compute: average active threads per executed instruction of the
# lighting kernels of a restir frame (quickstart, 320x180, frames 0-1; the
# BLAS builds, measured before, are left out: their replay is slow and
# failed once). The OptiX launches alternate G-buffer and shadow rays.
step_ncu() {
    local t="$W/ncu"
    mkdir -p "$t"
    timeout 400 ncu --metrics smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum \
        --kernel-name regex:"Kernel|optixLaunch" --log-file "$t/ncu.log" -o "$t/profile" \
        $BIN scenes/quickstart.toml -D camera.width=320 -D camera.height=180 -D render.estimator=restir \
        --frames 0:2 --repeat 1 -o "$t/q.{frame}.exr" > "$t/run.log" 2>&1
    ncu --import "$t/profile.ncu-rep" --csv --page raw \
        --metrics smsp__thread_inst_executed_per_inst_executed.ratio,gpu__time_duration.sum > "$t/ncu.csv" 2>&1
    rm -f "$t"/*.gpuframe
    head -5 "$t/ncu.csv"
}

# A change that must not move a GPU frame: the twin of the source tree in
# .twin-deps/old (staged by `bash bench/gpu/stage_deps.sh SDK OLD_COMMIT`)
# built beside this one, both run on every restir option the twin has and
# on particle_split, particle_restir and the voxel cache, and
# each pair of .gpuframe files compared plane by plane, byte for byte
# (bench/gpu/gpuframe_equal.py: the metadata records the run and differs).
step_identity() {
    local t="$W/identity" old=$D/old
    [ -d "$old" ] || { echo "identity: no $old (stage_deps.sh with an old commit)"; return 1; }
    mkdir -p "$t"
    build_twin "$old" "$(cat "$D/old.commit")" "$t/build_old.log" || { tail -20 "$t/build_old.log"; return 1; }
    local q0="scenes/quickstart.toml -D camera.width=320 -D camera.height=180 -D render.estimator=\"restir\" --frames 0:3"
    local k=0 differ=0 q
    while read -r opts; do
        k=$((k + 1))
        # one run a frame, or the line's own --repeat (a persistent BVH refitted again in each run)
        q="$q0 --repeat 1"
        [[ $opts == *--repeat* ]] && q=$q0
        # shellcheck disable=SC2086  # the overrides are words
        $BIN $q $opts -o "$t/new$k.{frame}.exr" > "$t/new$k.log" 2>&1 || { echo "identity: new twin failed on: $opts"; tail -3 "$t/new$k.log"; differ=1; continue; }
        # shellcheck disable=SC2086
        (cd "$old" && build-gpu/accretion-optix $q $opts -o "$t/old$k.{frame}.exr" > /dev/null 2>&1) ||
            { echo "identity: old twin failed on: $opts"; differ=1; continue; }
        for f in "$t"/new$k.*.gpuframe; do
            python3 bench/gpu/gpuframe_equal.py "$f" "${f/new$k/old$k}" && echo "same    $k $(basename "$f") $opts" || { echo "DIFFERS $k $(basename "$f") $opts"; differ=1; }
        done
    done <<'CONFIGS'
-D restir.bias_correction="pairwise"
-D restir.bias_correction="basic"
-D restir.bias_correction="none"
-D restir.bias_correction="basic" -D restir.visibility_reuse=true
-D render.source="power" -D restir.spatial_iterations=2 -D restir.spatial_neighbours=10
-D render.source="power" -D restir.resolution_scale=0.5
-D geometry.alpha="disc" -D restir.spatial_neighbours=64
-D geometry.layout="aabbs" -D restir.m_cap=5
-D geometry.layout="instances" -D geometry.build="refit" --repeat 3
-D geometry.build="partial" -D render.source="power" --repeat 3
-D geometry.build="refit" -D geometry.cluster_size=1000 --repeat 3
-D render.estimator="exact"
-D render.estimator="power" -D render.samples=8 -D geometry.alpha="disc"
-D render.estimator="uniform" -D render.samples=4 -D render.target_stderr=0.05 -D render.max_samples=16
-D particles.gm=0 -D camera.path="static"
-D render.estimator="particle_split" -D particle_split.near=8 -D particle_split.far=4 -D particle_split.candidates=8 -D particle_split.history=0.75
-D render.estimator="particle_split" -D particle_split.near=16 -D particle_split.far=8 -D particle_split.candidates=8 -D particle_split.texels=2
-D render.estimator="particle_restir" -D render.source="tree" -D restir.texel_rays=4 -D restir.spatial_neighbours=5 -D restir.bias_correction="pairwise"
-D render.estimator="particle_restir" -D render.source="tree" -D restir.texel_rays=4 -D restir.spatial_neighbours=0 -D restir.pixel_shading="resample"
-D render.estimator="voxel_cache" -D render.source="tree" -D voxel.cells=32 -D voxel.rays=8 -D voxel.basis="camera"
CONFIGS
    rm -f "$t"/*.gpuframe
    return $differ
}

# This tree's twin against the old tree's (stage_deps.sh with OLD_COMMIT),
# timed side by side: disk_100k at 1920x1080, restir and power (8 spp), and
# quickstart's exact at 320x180; frame 1 after a history frame, 5 timed runs a frame,
# the two twins alternating AB_ROUNDS (3) times; per pass the median ms of
# each and their ratio (ab/ratios.csv).
step_ab() {
    local t="$W/ab" old=$D/old
    [ -d "$old" ] || { echo "ab: no $old (stage_deps.sh with an old commit)"; return 1; }
    mkdir -p "$t"
    [ -x "$old/build-gpu/accretion-optix" ] || build_twin "$old" "$(cat "$D/old.commit")" "$t/build_old.log" || return 1
    local hd="-D camera.width=1920 -D camera.height=1080"
    local configs=("restir|scenes/disk_100k.toml -D render.estimator=restir $hd"
                   "power|scenes/disk_100k.toml -D render.estimator=power -D render.samples=8 $hd"
                   "exact|scenes/quickstart.toml -D render.estimator=exact -D camera.width=320 -D camera.height=180")
    for round in $(seq "${AB_ROUNDS:-3}"); do
        for c in "${configs[@]}"; do
            for side in new old; do
                local bin=$BIN dir=.
                [ $side = old ] && bin=$old/build-gpu/accretion-optix && dir=$old
                # shellcheck disable=SC2086  # the overrides are words
                (cd "$dir" && timeout 200 "$bin" ${c#*|} --frames 0:2 --repeat 5 -q -o "$t/x.{frame}.exr" \
                    --timings "$t/${c%%|*}.$side.$round.csv" --config "${c%%|*}" < /dev/null > /dev/null 2>&1) || echo "ab: $side ${c%%|*} failed"
                rm -f "$t"/*.gpuframe "$t"/*.json
            done
        done
    done
    python3 - "$t" <<'PY'
import csv, glob, statistics, sys, collections
t = sys.argv[1]
ms = collections.defaultdict(list)  # (config, pass, side) -> per round
for f in glob.glob(f"{t}/*.csv"):
    name = f.split("/")[-1].split(".")
    if len(name) != 4: continue
    for r in csv.DictReader(open(f)):
        ms[(name[0], r["pass"], name[1])].append(float(r["ms"]))
rows = ["config,pass,new_ms,old_ms,new_over_old"]
for (config, p, side) in sorted(ms):
    if side != "new" or (config, p, "old") not in ms: continue
    n, o = statistics.median(ms[(config, p, "new")]), statistics.median(ms[(config, p, "old")])
    rows.append(f"{config},{p},{n:.4f},{o:.4f},{n / o if o else float('nan'):.3f}")
open(f"{t}/ratios.csv", "w").write("\n".join(rows) + "\n")
print("\n".join(rows))
PY
}

# The ReSTIR steps and pass bodies the CPU and the twin share (restir_steps.h,
# restir_passes.h), run on this GPU and on its host CPU on the same inputs
# (tests/twin/shared_core_check.cu): bit for bit, neighbourPoint's cos and sin
# within CUDA's documented bound. Then the same check built with FMA
# contraction on the device (-fmad=true, which the twin never uses), which it
# must catch: a check that cannot fail proves nothing.
step_shared_core() {
    mkdir -p "$W/shared_core"
    local flags=(-std=c++20 -O3 --expt-relaxed-constexpr -diag-suppress=20012,20011,20014,20044 -arch=sm_90 -Iinclude -I"$S/include")
    # The library (particle_split's step builds a LightTree): the twin's build's (step build first).
    [ -f build-gpu/libaccretion_base.a ] || { echo "shared_core: run the build step first (build-gpu/libaccretion_base.a)"; return 1; }
    local src=(tests/twin/shared_core_check.cu build-gpu/libaccretion_base.a -L"$L" -ltomlplusplus -ltbb -lfmt -ldl -lpthread)
    nvcc "${flags[@]}" -fmad=false "${src[@]}" -o "$W/shared_core/check" &&
        nvcc "${flags[@]}" -fmad=true "${src[@]}" -o "$W/shared_core/check_fma" || return 1
    { echo "commit $(cat "$D/commit")"; nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
      "$W/shared_core/check"; } | tee "$W/shared_core/result.txt"
    local rc=${PIPESTATUS[0]}
    "$W/shared_core/check_fma" > "$W/shared_core/result_fma.txt"
    local fma=$?
    echo "the same check with -fmad=true on the device: exit $fma ($(grep -c 'differ in some bit' "$W/shared_core/result_fma.txt") steps reported; $(tail -1 "$W/shared_core/result_fma.txt"))" |
        tee -a "$W/shared_core/result.txt"
    grep -v ': 0 differ' "$W/shared_core/result_fma.txt" | grep 'cases:' | tee -a "$W/shared_core/result.txt"
    rm -f "$W/shared_core/check" "$W/shared_core/check_fma"
    [ "$rc" -eq 0 ] && [ "$fma" -eq 1 ]
}

for s in "$@"; do
    echo "== $s"
    "step_$s" || { echo "step $s failed"; break; }
    # What comes back: one archive per step (the device tool returns at most 8 files).
    if [ -d "$W/$s" ]; then tar czf "$OUT/$s.tar.gz" -C "$W" "$s" && rm -rf "${W:?}/$s"; fi
done
ls -la "$OUT"
