#!/usr/bin/env python3
"""Per configuration, what the held-out fits of designs_fit.sh said of it:
calibrate's JSON (-o) of each split seed, its per_pass held-out rows. For
each configuration held out at least once: its frame (the timed passes
summed) predicted against measured in every split that held it out, and
the same for its spatial reuse passes where they ran twice or more.
  python3 bench/gpu/designs_holdout.py CALIBRATION.json... > summary.txt"""
import collections
import json
import sys

frames, spatial = collections.defaultdict(list), collections.defaultdict(list)
for path in sys.argv[1:]:
    rows = json.load(open(path))["holdout"]["per_pass"]["rows"]
    frame, reuse = {}, {}
    for r in rows:
        f = frame.setdefault(r["config"], [0.0, 0.0])
        f[0] += r["measured_ms"]
        f[1] += r["predicted_ms"]
        if r["pass"].split("[")[0] in ("spatialResampling", "resampleWorldNeighbours"):
            s = reuse.setdefault(r["config"], [0.0, 0.0, 0])
            s[0] += r["measured_ms"]
            s[1] += r["predicted_ms"]
            s[2] += 1
    for config, (m, p) in frame.items():
        frames[config].append(p / m - 1.0)
    for config, (m, p, runs) in reuse.items():
        if runs >= 2:
            spatial[config].append(p / m - 1.0)


def table(title, errors, bound):
    worst = sorted(errors.items(), key=lambda kv: -max(abs(e) for e in kv[1]))
    within = sum(1 for _, es in worst if max(abs(e) for e in es) <= bound)
    print(f"{title}: {within} of {len(worst)} configurations within {bound:.0%} in every split that held them out")
    for config, es in worst:
        print(f"  {config:40s} worst {max(abs(e) for e in es):6.1%}  " + " ".join(f"{e:+.0%}" for e in es))


table("frames", frames, 0.10)
print()
table("spatial reuse run twice", spatial, 0.30)
