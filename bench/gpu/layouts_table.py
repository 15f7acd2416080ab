#!/usr/bin/env python3
"""The layout decision matrix from the twin's stats JSONs (bench/gpu/run.sh
steps layouts and streams): one row per configuration, frame 1 (after a
history frame), median GPU ms per pass and the acceleration structure's
memory.  Usage: layouts_table.py OUT.csv DIR..."""
import csv
import glob
import json
import os
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
from pass_names import PASS  # noqa: E402

NAME = re.compile(r"p(\d+)_(\d+)x(\d+)_(.+)")


def variant(rest):
    """layout, primitive, cluster size, build policy, host threads, streams of a row name's tail."""
    layout, primitive, cluster, build, threads, streams = "clusters", "billboard", "", "rebuild", 1, 1
    for word in rest.split("_"):
        if word in ("instances", "aabbs"):
            layout = word
        elif word == "spheres":
            primitive = "sphere"
        elif word == "one":
            cluster = "all"
        elif word.startswith("k") and word[1:].isdigit():
            cluster = word[1:]
        elif word == "refit":
            build = "refit"
        elif word.startswith("threads"):
            threads = int(word[7:])
        elif word.startswith("streams"):
            streams = int(word[7:])
    if layout == "instances":
        cluster = "1 (instance)"
    return layout, primitive, cluster, build, threads, streams


def main():
    out, dirs = sys.argv[1], sys.argv[2:]
    rows = []
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "*.0000.gpu_stats.json"))):
            name = os.path.basename(path).split(".")[0]
            m = NAME.fullmatch(name)
            if not m:
                continue
            j = json.load(open(path))
            f = j["frames"][-1]
            ms = {k: v["median_ms"] for k, v in f["gpu_ms"].items()}
            layout, primitive, cluster, build, threads, streams = variant(m.group(4))
            expand = ms.get("expandPrimitives", 0.0) + ms.get("writeInstances", 0.0)
            restir = sum(ms.get(p, 0.0) for p in (PASS.generateCandidates, PASS.temporalResampling, PASS.spatialResampling))
            rows.append({
                "config": name, "commit": j["version"].split("+")[-1], "gpu": j["device"],
                "particles": int(m.group(1)), "width": int(m.group(2)), "height": int(m.group(3)),
                "layout": layout, "primitive": primitive, "cluster_size": cluster, "build": build,
                "host_threads": threads, "build_streams": streams,
                "blases": f["blases"], "instances": f["instances"], "primitives": f["primitives"],
                "largest_blas_primitives": f["largest_blas_primitives"],
                "expand_ms": round(expand, 4), "blas_ms": round(ms.get("buildBlas", 0.0), 4),
                "tlas_ms": round(ms.get("buildTlas", 0.0), 4),
                "build_ms": round(expand + ms.get("buildBlas", 0.0) + ms.get("buildTlas", 0.0), 4),
                "gbuffer_ms": round(ms.get(PASS.traceGBuffer, 0.0), 4), "restir_ms": round(restir, 4),
                "shadow_ms": round(ms.get(PASS.traceShadowRays, 0.0), 4),
                "frame_ms": round(sum(ms.values()), 4),
                "blas_enqueue_ms": round(f["blas_enqueue_ms"], 3),
                "blas_bytes": f["blas_bytes"], "tlas_bytes": f["tlas_bytes"], "scratch_bytes": f["scratch_bytes"],
                "input_bytes": f["input_bytes"], "accel_bytes": f["accel_total_bytes"],
                "shadow_rays": f["shadow_rays"], "any_hits": f["any_hits"],
            })
    rows.sort(key=lambda r: (r["particles"], r["width"], r["layout"], r["primitive"], r["build"],
                             r["host_threads"], r["build_streams"],
                             -1 if r["cluster_size"] == "all" else int(re.sub(r"\D.*", "", r["cluster_size"]) or 0)))
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"{out}: {len(rows)} rows")


if __name__ == "__main__":
    main()
