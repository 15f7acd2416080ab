#!/usr/bin/env python3
"""The twin's own counts against `accretion cost`'s, per sweep configuration:
shadow rays and their any-hit invocations (the twin's counting run of the
timed frame, from its stats JSON; cost's traceShadowRays row).

    python3 bench/gpu/counts_table.py SWEEP_DIR COUNTERS_CSV OUT_CSV"""
import csv, glob, json, os, pathlib, sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
from pass_names import PASS  # noqa: E402

sweep, counters, out = sys.argv[1:4]
cost = {(r["config"], r["pass"]): r for r in csv.DictReader(open(counters))}
with open(out, "w", newline="") as fh:
    w = csv.writer(fh)
    w.writerow(["config", "twin_shadow_rays", "cost_shadow_rays", "rays_ratio", "twin_any_hits", "cost_any_hits",
                "twin_retests"])
    for f in sorted(glob.glob(os.path.join(sweep, "*.gpu_stats.json"))):
        name = os.path.basename(f).split(".")[0]
        frame = json.load(open(f))["frames"][-1]
        c = cost.get((name, PASS.traceShadowRays))
        if not c:
            continue
        rays = frame["shadow_rays"] - frame.get("shadow_retests", 0)
        w.writerow([name, rays, int(float(c["rays"])), f"{rays / float(c['rays']):.4f}", frame["any_hits"],
                    int(float(c["any_hits"])), frame.get("shadow_retests", 0)])
print(open(out).read())
