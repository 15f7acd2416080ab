#!/usr/bin/env python3
"""One CSV of a run.sh step's timings (split_anatomy, ray_launch,
split_order): every CONFIG.timings.csv of the step's folder, per pass the
twin's median GPU ms, with the commit and GPU that measured it (env.txt of
the same device run; no RT cores on the H100).
  python3 bench/gpu/timings_csv.py STEP_DIR ENV_TXT > bench/gpu/results/STEP.csv"""
import csv
import pathlib
import sys

folder, env = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]).read_text().splitlines()
commit = env[-1].strip()  # run.sh env: the commit last
gpu = next(l.split(",")[0] for l in env if "NVIDIA" in l)
out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(["commit", "gpu", "rt_cores", "config", "pass", "ms"])
for f in sorted(folder.glob("*.timings.csv")):
    for r in csv.DictReader(f.open()):
        out.writerow([commit, gpu, "no", r["config"], r["pass"], r["ms"]])
