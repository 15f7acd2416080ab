# Sourced by bench/operating_point.sh and bench/designs.sh: tune's eight
# 160x90 crops of the 1920x1080 frame and their split references at 1024
# spp, with and without visibility, made in $out when absent; sets refs and
# unshadowed (bias's --reference and --unshadowed-reference arguments).
# Needs A, scene, D (the scene's overrides) and out; FRAME (20) is the
# measured frame, whose references these are. REFS=DIR takes (and makes)
# them in DIR instead of out: more seeds of a run whose references exist.
# tune's crops (cmd_tune.cpp errorCrops), printed by tune itself would need a
# whole search: the same strata and hash here.
crops=$(python3 - <<'PY'
M = (1 << 64) - 1
def mix64(x):
    x = (x + 0x9e3779b97f4a7c15) & M
    x = ((x ^ (x >> 30)) * 0xbf58476d1ce4e5b9) & M
    x = ((x ^ (x >> 27)) * 0x94d049bb133111eb) & M
    return x ^ (x >> 31)
cols, rows, cw, ch, W, H = 4, 2, 160, 90, 1920, 1080
sw, sh = W // cols, H // rows
for r in range(rows):
    for c in range(cols):
        h = mix64((0x9e3779b97f4a7c15 * (r * cols + c + 1)) & M)
        x0 = c * sw + (h & 0xffffffff) % (sw - cw + 1)
        y0 = r * sh + (h >> 32) % (sh - ch + 1)
        print(f"[{x0},{x0 + cw},{y0},{y0 + ch}]")
PY
)
refs=() unshadowed=() k=0
for c in $crops; do
    for vis in true false; do
        f=${REFS:-$out}/ref$k.$vis.exr
        [ -f "$f" ] || "$A" render $scene "${D[@]}" -D "render.crop=$c" -D shading.visibility=$vis --estimator split --spp 1024 \
            --frames ${FRAME:-20}:$((${FRAME:-20} + 1)) -o "$f" --quiet > /dev/null
    done
    refs+=(--reference "${REFS:-$out}/ref$k.true.exr")
    unshadowed+=(--unshadowed-reference "${REFS:-$out}/ref$k.false.exr")
    k=$((k + 1))
done
