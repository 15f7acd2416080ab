#!/usr/bin/env bash
# Compiles the OptiX twin (src/twin) without a GPU, as CI does: the OptiX
# programs to OptiX-IR, the CUDA kernels and the host code to objects, and
# links accretion-optix against the Release build's accretion_base. Beside
# them the check of the steps the CPU and the twin share (restir_steps.h,
# particle_split_passes.h, ...) on the GPU against the CPU
# (tests/twin/shared_core_check.cu) is compiled; it runs when this machine
# has a GPU. GPU runs stay on a GPU machine
# (bench/gpu/run.sh).
#   scripts/compile_twin.sh [BUILD_DIR]      (default build: the Release build)
# nvcc: $NVCC, else nvcc on PATH, else /usr/local/cuda, else CUDA 13's
# compiler wheels from the Python package index in .cache/cuda (Debian has
# no nvcc). OptiX headers: $OPTIX_INCLUDE, else ../shared/optix-9.0/include.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
out=build-twin
mkdir -p "$out"

# The directory holding cuda_runtime.h, as this nvcc itself would search it
# (its INCLUDES, from a dry run), or nothing: an nvcc installed alone, or
# reached through a link on PATH, may come without the runtime headers.
cuda_include() {
    local dir
    for dir in $("$1" --dryrun -x cu -c /dev/null -o /dev/null 2>&1 | sed -n 's/^#\$ INCLUDES=//p' | tr -d '"' | sed 's/-I/ /g'); do
        [ -f "$dir/cuda_runtime.h" ] && { (cd "$dir" && pwd); return; }
    done
    return 0
}
nvcc=${NVCC:-$(command -v nvcc || true)}
[ -n "$nvcc" ] || [ ! -x /usr/local/cuda/bin/nvcc ] || nvcc=/usr/local/cuda/bin/nvcc
[ -z "$nvcc" ] || nvcc=$(readlink -f "$nvcc")
cuda_inc=
[ -z "$nvcc" ] || cuda_inc=$(cuda_include "$nvcc")
# Else the runtime headers installed apart from it (e.g. the cudart wheel in
# another site-packages folder than the nvcc wheel's).
if [ -n "$nvcc" ] && [ -z "$cuda_inc" ]; then
    h=$(find /usr/local /usr/lib /opt "$HOME/.local" -name cuda_runtime.h -path '*include*' 2>/dev/null | head -1 || true)
    [ -z "$h" ] || cuda_inc=$(dirname "$h")
fi
if [ -z "$cuda_inc" ]; then
    [ -z "$nvcc" ] || echo "compile_twin: $nvcc has no cuda_runtime.h on its include path; using the PyPI wheels" >&2
    venv=.cache/cuda
    if [ ! -x "$venv/bin/python" ] || [ -z "$(find "$venv" -path '*/nvidia/cu13/bin/nvcc' | head -1)" ]; then
        echo "compile_twin: installing CUDA 13's nvcc, runtime headers and cudart from PyPI into $venv" >&2
        python3 -m venv "$venv"
        "$venv/bin/pip" install -q "cuda-toolkit[nvcc,cudart,crt,nvvm,cccl]==13.0.*"
    fi
    nvcc=$(find "$venv" -path '*/nvidia/cu13/bin/nvcc' | head -1)
    [ -x "$nvcc" ] || { echo "compile_twin: no nvcc in $venv" >&2; exit 1; }
    cuda_inc=$(cuda_include "$nvcc")
    [ -n "$cuda_inc" ] || { echo "compile_twin: no cuda_runtime.h for $nvcc" >&2; exit 1; }
fi
cuda=$(cd "$(dirname "$nvcc")/.." && pwd)
optix=${OPTIX_INCLUDE:-../shared/optix-9.0/include}
[ -f "$optix/optix.h" ] || { echo "compile_twin: no optix.h in '$optix' (set OPTIX_INCLUDE)" >&2; exit 1; }
[ -f "$build/libaccretion_base.a" ] || { echo "compile_twin: no $build/libaccretion_base.a (build the project first)" >&2; exit 1; }
echo "compile_twin: $nvcc ($("$nvcc" --version | tail -2 | head -1)), CUDA headers $cuda_inc, OptiX headers $optix" >&2

# The flags of src/twin/CMakeLists.txt: no FMA contraction, so that the
# shared ACC_HD functions round as the CPU's do.
cuflags=(-std=c++20 -O3 -fmad=false --expt-relaxed-constexpr -diag-suppress=20012,20011,20014,20044 -arch=sm_90
         -Iinclude -Isrc/twin -I"$optix" -I"$build/generated" -I"$cuda_inc")
cxxflags=(-std=c++20 -O2 -Wall -Wextra -Wno-unused-parameter -Iinclude -Isrc/twin -I"$optix" -I"$cuda_inc")

cudart=$(find "$cuda" "$(dirname "$cuda_inc")" \( -name 'libcudart.so*' -o -name 'libcudart_static.a' \) 2>/dev/null | head -1)
pids=()
# The shared steps checked where they run: on the GPU against the CPU
# (tests/twin/shared_core_check.cu). Compiled on every run, beside the twin's
# files (alone after them it kept one core idle for 11 s); run below only
# where there is a GPU (bench/gpu/run.sh shared_core on the lent one).
"$nvcc" "${cuflags[@]}" tests/twin/shared_core_check.cu "$build/libaccretion_base.a" -L"$(dirname "$cudart")" -ltomlplusplus -ltbb \
    -lfmt -ldl -lpthread -o "$out/shared_core_check" & pids+=($!)  # the library: particle_split's step builds a LightTree
"$nvcc" "${cuflags[@]}" -optix-ir -c src/twin/programs.cu -o "$out/programs.optixir" & pids+=($!)
for f in kernels restir_kernels gather_particle_texels voxel_kernels split_kernels; do
    "$nvcc" "${cuflags[@]}" -c src/twin/$f.cu -o "$out/$f.o" & pids+=($!)
done
for f in twin_main optix_pipeline particle_accel; do
    g++ "${cxxflags[@]}" -DACCRETION_TWIN_PROGRAMS="\"$out/programs.optixir\"" -c src/twin/$f.cpp -o "$out/$f.o" & pids+=($!)
done
for p in "${pids[@]}"; do wait "$p"; done
"$nvcc" -arch=sm_90 "$out"/{twin_main,optix_pipeline,particle_accel,kernels,restir_kernels,gather_particle_texels,voxel_kernels,split_kernels}.o \
    "$build/libaccretion_base.a" -L"$(dirname "$cudart")" -ltomlplusplus -ltbb -lfmt -ldl -lpthread -o "$out/accretion-optix"
echo "compile_twin: $out/accretion-optix and $out/programs.optixir" >&2

if command -v nvidia-smi >/dev/null 2>&1 && nvidia-smi -L >/dev/null 2>&1; then
    "$out/shared_core_check"
else
    echo "compile_twin: $out/shared_core_check compiled; no GPU here to run it on (bench/gpu/run.sh shared_core)" >&2
fi
