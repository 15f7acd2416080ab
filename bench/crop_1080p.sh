#!/usr/bin/env bash
# Crops and single pixels at frame speed. disk_100k
# frame 0 at 1920x1080, `split` at SPP samples (k from the pilot: one k for
# the view, whatever the window), windows of 1x1 to 256x256 pixels about
# (1000, 600) and the whole frame, RUNS runs each, interleaved; then one
# pixel at MANY samples. Per window: the median of each pass's seconds
# (stats.json), the process's wall time and peak memory, the lit pixels.
# Prints the per-frame part (passes that do not depend on the window), the
# per-pixel part against the whole frame's per pixel (a ratio of the same
# run), and the shadow rays per second of the one pixel against the frame's.
#   bench/crop_1080p.sh [SPP [RUNS [MANY]]]       (default: 64 3 65536)
# Writes bench/crop_1080p.csv and bench/crop_1080p.json.
set -euo pipefail
cd "$(dirname "$0")/.."
spp=${1:-64} runs=${2:-3} many=${3:-65536}
bin=${ACCRETION:-./build/accretion}
export ACCRETION=$bin  # scripts/pass_names.py asks it for the pass table
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
csv=bench/crop_1080p.csv
# A column per top-level pass (restir's passes are timed inside estimateLighting).
top=$(python3 -c 'import sys; sys.path.insert(0, "scripts"); from pass_names import TABLE; print(",".join(p["name"] for p in TABLE if p["parent"] is None))')
echo "window,pixels,spp,run,wall_s,peak_rss_mb,frame_s,lit_pixels,shadow_rays,$top" > "$csv"
one() {  # one render: window (x0,x1,y0,y1 or whole), samples, run
  local crop=() name=$1
  [ "$1" != whole ] && crop=(--crop "$1")
  /usr/bin/time -f "%e %M" -o "$out/time" "$bin" render scenes/disk_100k.toml --quiet --estimator split --spp "$2" \
      -D camera.width=1920 -D camera.height=1080 "${crop[@]}" --frames 0 -o "$out/r.exr" > /dev/null
  python3 - "$out/r.stats.json" "$out/time" "$name" "$2" "$3" >> "$csv" <<'PY'
import json, sys
sys.path.insert(0, "scripts")
from pass_names import TABLE
f = json.load(open(sys.argv[1]))["frames"][0]
wall, rss = open(sys.argv[2]).read().split()
w = sys.argv[3]
if w == "whole":
    pixels = 1920 * 1080
else:
    x0, x1, y0, y1 = map(int, w.split(","))
    pixels = (x1 - x0) * (y1 - y0)
p = f["passes"]
names = [t["name"] for t in TABLE if t["parent"] is None]
print(",".join([w.replace(",", " "), str(pixels), sys.argv[4], sys.argv[5], wall, f"{int(rss) / 1024:.0f}", f"{f['seconds']:.4f}",
                str(f["counts"]["hit_pixels"]), str(f["rays"]["shadow"])] + [f"{p.get(n, 0.0):.4f}" for n in names]))
PY
  tail -1 "$csv" >&2
}
windows=(1000,1001,600,601 992,1008,592,608 968,1032,568,632 872,1128,472,728 whole)
for r in $(seq "$runs"); do
  for w in "${windows[@]}"; do one "$w" "$spp" "$r"; done
done
for r in $(seq "$runs"); do one 1000,1001,600,601 "$many" "$r"; done
python3 - "$csv" "$(git rev-parse --short=10 HEAD)" "$(nproc)" "$spp" "$many" <<'PY'
import csv, json, statistics, sys
sys.path.insert(0, "scripts")
from pass_names import PASS, TABLE
rows = list(csv.DictReader(open(sys.argv[1])))
commit, cores, spp, many = sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
# Per frame: the host's work and the builds (one thread per cluster), whatever
# the window; per pixel: the top-level passes with a thread per pixel.
top = [t for t in TABLE if t["parent"] is None and t["name"] != PASS.writeOutputs]
frame_passes = [t["name"] for t in top if t["grid"] in ("host", "clusters")]
pixel_passes = [t["name"] for t in top if t["grid"] == "pixels"]
med = lambda rs, k: statistics.median(float(r[k]) for r in rs)
res = {"commit": commit, "cores": cores, "scene": f"disk_100k frame 0, 1920x1080, split, k from the pilot", "spp": spp,
       "windows": []}
whole = [r for r in rows if r["window"] == "whole"]
w_light, w_lit = med(whole, PASS.estimateLighting), med(whole, "lit_pixels")
print(f"{'window':>20} {'pixels':>8} {'lit':>7} {'wall s':>7} {'MB':>5} {'per frame s':>11} {'per pixel s':>11} {'lighting s per lit px, / frame':>31}")
for name in dict.fromkeys(r["window"] for r in rows if int(r["spp"]) == spp):
    rs = [r for r in rows if r["window"] == name and int(r["spp"]) == spp]
    per_frame = sum(med(rs, k) for k in frame_passes)
    per_pixel = sum(med(rs, k) for k in pixel_passes)
    lit = med(rs, "lit_pixels")
    ratio = (med(rs, PASS.estimateLighting) / lit) / (w_light / w_lit) if lit else float("nan")
    e = {"window": name, "pixels": int(rs[0]["pixels"]), "lit_pixels": lit, "wall_s": med(rs, "wall_s"),
         "peak_rss_mb": med(rs, "peak_rss_mb"), "frame_s": med(rs, "frame_s"), "per_frame_s": per_frame,
         "per_pixel_s": per_pixel, "lighting_per_lit_pixel_vs_whole": ratio,
         "passes": {k: med(rs, k) for k in frame_passes + pixel_passes + [PASS.writeOutputs]}}
    res["windows"].append(e)
    print(f"{name:>20} {e['pixels']:>8} {lit:>7.0f} {e['wall_s']:>7.2f} {e['peak_rss_mb']:>5.0f} {per_frame:>11.3f} {per_pixel:>11.3f} {ratio:>31.2f}")
one = [r for r in rows if int(r["spp"]) == many]
if one:
    rays_one = med(one, "shadow_rays") / med(one, PASS.estimateLighting)
    rays_whole = med(whole, "shadow_rays") / w_light
    res["one_pixel_many"] = {"spp": many, "wall_s": med(one, "wall_s"), "estimateLighting_s": med(one, PASS.estimateLighting),
                             "shadow_rays_per_s": rays_one, "whole_frame_shadow_rays_per_s": rays_whole,
                             "whole_frame_shadow_rays_per_s_per_core": rays_whole / cores}
    print(f"one pixel at {many} spp: {med(one, 'wall_s'):.2f} s wall, estimateLighting {med(one, PASS.estimateLighting):.3f} s, "
          f"{rays_one / 1e6:.2f} M shadow rays/s on one core; the whole frame at {spp} spp: {rays_whole / 1e6:.2f} M/s on {cores} "
          f"cores ({rays_whole / cores / 1e6:.2f} M/s per core)")
print(f"commit {commit}, {cores} cores")
json.dump(res, open("bench/crop_1080p.json", "w"), indent=1)
PY
