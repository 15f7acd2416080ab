#!/usr/bin/env python3
"""The H100's per-pass ms of results/designs.csv, as the cost model's fit
and designs_priced.py read them: {config: {pass: ms}}, the last row of a
(config, pass) winning.

particle_restir's resample variant was timed under the label
shadeParticlePixels until aaf54f8, which gave it a pass of its own,
resampleParticlePixels. Its kernel did not change (run.sh identity at
a9b73ceee2 against 9e58491dce: every frame the same, byte for byte,
results/identity_designs.txt), so its H100 rows are read under the new name:
the configurations whose overrides set restir.pixel_shading=resample
(designs.txt, designs_cluster.txt).
  python3 bench/gpu/designs_timings.py [REGEX]   config,pass,ms lines of the configurations matching REGEX"""
import csv
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]


def resample_configs():
    names = set()
    for lst in ("bench/gpu/designs.txt", "bench/gpu/designs_cluster.txt"):
        for line in (ROOT / lst).read_text().splitlines():
            if line.strip() and not line.startswith("#") and "restir.pixel_shading=resample" in line.split("#", 1)[0]:
                names.add(line.split()[0])
    return names


def h100_timings():
    resample = resample_configs()
    measured = {}
    for r in csv.DictReader((ROOT / "bench/gpu/results/designs.csv").open()):
        if "H100" not in r["gpu"]:
            continue
        p = r["pass"]
        if r["config"] in resample and p == "shadeParticlePixels":
            p = "resampleParticlePixels"
        measured.setdefault(r["config"], {})[p] = float(r["ms"])
    return measured


if __name__ == "__main__":
    pattern = re.compile(sys.argv[1] if len(sys.argv) > 1 else "")
    for config, passes in h100_timings().items():
        if pattern.search(config):
            for p, ms in passes.items():
                if p != "frame":
                    print(f"{config},{p},{ms}")
