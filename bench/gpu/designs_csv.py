#!/usr/bin/env python3
"""bench/gpu/results/designs.csv from run.sh's designs step: per
configuration of bench/gpu/designs.txt and designs_cluster.txt (the
cluster_150k scene, particles 150000) and per pass the twin's median GPU
ms (5 timed runs of frame 1 after a history frame), the frame's total, and
the commit and GPU that measured it (env.txt of the same archive).
  python3 bench/gpu/designs_csv.py DESIGNS_DIR ENV_TXT > bench/gpu/results/designs.csv"""
import csv
import pathlib
import sys

folder, env = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]).read_text().splitlines()
commit = env[-1].strip()  # run.sh env: the commit last
gpu = next(l.split(",")[0] for l in env if "NVIDIA" in l)
what = {}
for lst in ("bench/gpu/designs.txt", "bench/gpu/designs_cluster.txt"):
    for line in pathlib.Path(lst).read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        what[line.split()[0]] = line.split("#", 1)[1].strip() if "#" in line else ""
out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(["commit", "gpu", "rt_cores", "particles", "config", "design", "pass", "ms"])
for name in what:
    f = folder / ("cluster" if name.endswith("_cluster") else "") / f"{name}.timings.csv"
    if not f.exists():
        continue
    passes = {r["pass"]: float(r["ms"]) for r in csv.DictReader(f.open())}
    particles = 1000000 if name.endswith("_1m") else 150000 if name.endswith("_cluster") else 100000
    for p, ms in passes.items():
        out.writerow([commit, gpu, "no", particles, name, what[name], p, f"{ms:.4f}"])
    out.writerow([commit, gpu, "no", particles, name, what[name], "frame", f"{sum(passes.values()):.4f}"])
