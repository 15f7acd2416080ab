#!/usr/bin/env python3
"""bench/gpu/results/designs.csv from run.sh's designs step: per
configuration of bench/gpu/designs.txt and designs_cluster.txt (the
cluster_150k scene, particles 150000) and per pass the twin's median GPU
ms (5 timed runs of frame 1 after a history frame), the frame's total, and
the commit and GPU that measured it (env.txt of the same archive).
  python3 bench/gpu/designs_csv.py DESIGNS_DIR ENV_TXT > bench/gpu/results/designs.csv
With --into CSV [--only REGEX]: CSV again, the configurations DESIGNS_DIR
timed (those matching REGEX) replaced by its rows, where they stood (a step
that timed some configurations again: voxels, splits, iterations).
  python3 bench/gpu/designs_csv.py out/voxels ENV_TXT --into bench/gpu/results/designs.csv --only '^vox_'"""
import argparse
import csv
import io
import pathlib
import re
import sys

ap = argparse.ArgumentParser()
ap.add_argument("folder", type=pathlib.Path)
ap.add_argument("env", type=pathlib.Path)
ap.add_argument("--into", type=pathlib.Path)
ap.add_argument("--only", default="")
args = ap.parse_args()
folder, env = args.folder, args.env.read_text().splitlines()
commit = env[-1].strip()  # run.sh env: the commit last
gpu = next(l.split(",")[0] for l in env if "NVIDIA" in l)
what = {}
for lst in ("bench/gpu/designs.txt", "bench/gpu/designs_cluster.txt"):
    for line in pathlib.Path(lst).read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        what[line.split()[0]] = line.split("#", 1)[1].strip() if "#" in line else ""
header = ["commit", "gpu", "rt_cores", "particles", "config", "design", "pass", "ms"]
timed = io.StringIO()
out = csv.writer(timed, lineterminator="\n")
for name in what:
    if not re.search(args.only, name):
        continue
    f = folder / ("cluster" if name.endswith("_cluster") else "") / f"{name}.timings.csv"
    if not f.exists():
        continue
    passes = {r["pass"]: float(r["ms"]) for r in csv.DictReader(f.open())}
    particles = 1000000 if name.endswith("_1m") else 150000 if name.endswith("_cluster") else 100000
    for p, ms in passes.items():
        out.writerow([commit, gpu, "no", particles, name, what[name], p, f"{ms:.4f}"])
    out.writerow([commit, gpu, "no", particles, name, what[name], "frame", f"{sum(passes.values()):.4f}"])

final = csv.writer(sys.stdout, lineterminator="\n")
final.writerow(header)
new_rows = list(csv.reader(io.StringIO(timed.getvalue())))
if args.into is None:
    final.writerows(new_rows)
    sys.exit(0)
by_config = {}
for r in new_rows:
    by_config.setdefault(r[4], []).append(r)
replaced = set()
for r in csv.DictReader(args.into.open()):
    if r["config"] in by_config:  # the new rows where its first row stood
        final.writerows(by_config.pop(r["config"]))
        replaced.add(r["config"])
    if r["config"] not in replaced:
        final.writerow([r[k] for k in header])
for rows in by_config.values():  # configurations the file did not hold
    final.writerows(rows)
