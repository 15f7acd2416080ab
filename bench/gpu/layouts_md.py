#!/usr/bin/env python3
"""docs/layouts.md's table from bench/gpu/results/layouts.csv: per layout at
1920x1080, 100K and 1M particles, GPU ms of the build (primitive expansion +
BLAS builds + TLAS), the G-buffer, lighting (candidates + temporal +
spatial), shadow rays and the frame, and the acceleration structure's MB.
Usage: layouts_md.py [layouts.csv]"""
import csv
import pathlib
import sys

ROWS = [  # (label, configuration name after p<N>_1920x1080_)
    ("clusters of 25", "k25"), ("**clusters of 100 (seed 004)**", "k100"), ("clusters of 100, refit", "k100_refit"),
    ("clusters of 1000", "k1000"), ("clusters of 1000, refit", "k1000_refit"), ("clusters of 10000", "k10000"),
    ("clusters of 10000, refit", "k10000_refit"), ("one triangle BLAS", "one"), ("one triangle BLAS, refit", "one_refit"),
    ("instance per particle", "instances"), ("instance per particle, TLAS refit", "instances_refit"),
    ("one BLAS of procedural boxes", "aabbs_one"), ("one BLAS of procedural boxes, refit", "aabbs_one_refit"),
    ("boxes, clusters of 1000", "aabbs_k1000"), ("boxes, clusters of 1000, refit", "aabbs_k1000_refit"),
    ("one BLAS of built-in spheres (another primitive)", "spheres_one"),
    ("one BLAS of built-in spheres, refit", "spheres_one_refit"),
]


def ms(x):
    v = float(x)
    return f"{v:.1f}" if v >= 100 else f"{v:.2f}"


def main(path):
    rows = {r["config"]: r for r in csv.DictReader(open(path, newline=""))}
    commits = sorted({rows[f"p{n}_1920x1080_{c}"]["commit"] for _, c in ROWS for n in (100000, 1000000)})
    print(f"<!-- bench/gpu/layouts_md.py {path}: rows measured at {', '.join(commits)} -->")
    print("| layout | 100K: build | G-buffer | lighting | shadow rays | frame | memory MB "
          "| 1M: build | G-buffer | shadow rays | frame | memory MB |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, c in ROWS:
        a, b = rows[f"p100000_1920x1080_{c}"], rows[f"p1000000_1920x1080_{c}"]
        cells = [ms(a["build_ms"]), ms(a["gbuffer_ms"]), ms(a["restir_ms"]), ms(a["shadow_ms"]), ms(a["frame_ms"]),
                 f"{float(a['accel_bytes']) / 1e6:.1f}", ms(b["build_ms"]), ms(b["gbuffer_ms"]), ms(b["shadow_ms"]),
                 ms(b["frame_ms"]), f"{float(b['accel_bytes']) / 1e6:.1f}"]
        print(f"| {label} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(pathlib.Path(__file__).parent / "results" / "layouts.csv"))
