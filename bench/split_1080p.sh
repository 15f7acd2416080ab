#!/usr/bin/env bash
# The reference at the GPU team's resolution: disk_100k frame 0 at 1920x1080, `split`
# with k chosen by the pilot, at several sample counts; each run's wall
# time, its passes (stats.json) and its relMSE of Lr against an exact 1080p
# reference (made in row shards: docs/batches.md, "Shards"). Per k the
# pilot picked, fits time = a + b S and relMSE = v / S (v: the median of
# relMSE x S) and prints the samples and seconds to relMSE 1e-3 and 1e-2.
#   bench/split_1080p.sh REFERENCE.exr [SPP ...]      (default: 16 24 40 128 192 256)
# Writes bench/split_1080p.csv and bench/split_1080p.json.
set -euo pipefail
cd "$(dirname "$0")/.."
ref=${1:?usage: bench/split_1080p.sh REFERENCE.exr [SPP ...]}
shift
levels=("$@")
[ ${#levels[@]} -eq 0 ] && levels=(16 24 40 128 192 256)
bin=${ACCRETION:-./build/accretion}
export ACCRETION=$bin  # scripts/pass_names.py asks it for the pass table
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
csv=bench/split_1080p.csv
echo "spp,seconds,relMSE_Lr,near_lights,chooseNearLights_s,estimateLighting_s,other_s" > "$csv"
for spp in "${levels[@]}"; do
  start=$(date +%s.%N)
  "$bin" render scenes/disk_100k.toml --quiet --estimator split --spp "$spp" -D camera.width=1920 -D camera.height=1080 \
      --frames 0 -o "$out/s$spp.exr" > /dev/null
  end=$(date +%s.%N)
  rel=$("$bin" compare "$out/s$spp.exr" "$ref" --layer Lr --flip none --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin)["relMSE"])')
  python3 - "$out/s$spp.stats.json" "$spp" "$start" "$end" "$rel" >> "$csv" <<'PY'
import json, sys
sys.path.insert(0, "scripts")
from pass_names import PASS
stats, spp, start, end, rel = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
f = json.load(open(stats))["frames"][0]
p = f["passes"]
near = p.get(PASS.chooseNearLights, 0.0)
light = p.get(PASS.estimateLighting, 0.0)
print(f"{spp},{end - start:.2f},{rel:.6g},{f['counts']['near_lights']},{near:.3f},{light:.2f},{end - start - near - light:.2f}")
PY
  tail -1 "$csv" >&2
done
python3 - "$csv" "$(git rev-parse --short=10 HEAD)" "$(nproc)" <<'PY'
# One fit per k the pilot picked (it picks by S: a fit across two k would
# mix two estimators); each target's figure comes from the fastest k whose
# runs reach within 2x of the target's spp.
import csv, json, statistics, sys
rows = [r for r in csv.DictReader(open(sys.argv[1]))]
res = {"commit": sys.argv[2], "cores": int(sys.argv[3]), "scene": "disk_100k frame 0, 1920x1080, split, k from the pilot",
       "runs": rows, "fits": []}
for k in sorted({int(r["near_lights"]) for r in rows}):
    group = [r for r in rows if int(r["near_lights"]) == k]
    S = [float(r["spp"]) for r in group]; t = [float(r["seconds"]) for r in group]; e = [float(r["relMSE_Lr"]) for r in group]
    n = len(S); ms = sum(S) / n; mt = sum(t) / n
    b = sum((s - ms) * (y - mt) for s, y in zip(S, t)) / sum((s - ms) ** 2 for s in S) if n > 1 else t[0] / S[0]
    a = mt - b * ms
    v = statistics.median(x * s for x, s in zip(e, S))
    fit = {"near_lights": k, "spp": S, "fixed_s": a, "s_per_spp": b, "relMSE_x_spp": v}
    for target in (1e-3, 1e-2):
        spp = v / target
        fit[f"spp_to_{target:g}"] = spp
        fit[f"seconds_to_{target:g}"] = a + b * spp
        fit[f"within_range_{target:g}"] = min(S) / 2 <= spp <= 2 * max(S)
    res["fits"].append(fit)
    print(f"k = {k}: time = {a:.1f} s + {b:.3f} s x spp over {S}; relMSE x spp = {v:.3f}; "
          f"to 1e-3: {v/1e-3:.0f} spp, {a + b * v / 1e-3:.0f} s; to 1e-2: {v/1e-2:.0f} spp, {a + b * v / 1e-2:.0f} s")
for target in (1e-3, 1e-2):
    ok = [f for f in res["fits"] if f[f"within_range_{target:g}"]]
    if ok:
        best = min(ok, key=lambda f: f[f"seconds_to_{target:g}"])
        res[f"seconds_to_{target:g}"] = best[f"seconds_to_{target:g}"]
        res[f"spp_to_{target:g}"] = best[f"spp_to_{target:g}"]
        res[f"near_lights_to_{target:g}"] = best["near_lights"]
        print(f"relMSE {target:g}: {best[f'seconds_to_{target:g}']:.0f} s ({best[f'spp_to_{target:g}']:.0f} spp, k = {best['near_lights']})")
    else:
        print(f"relMSE {target:g}: no k's runs reach within 2x of its spp: add sample counts")
json.dump(res, open("bench/split_1080p.json", "w"), indent=1)
PY
