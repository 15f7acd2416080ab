#!/usr/bin/env python3
"""Tables of the OptiX twin's timing runs (bench/gpu/run.sh builds, frame, ncu).

    python3 bench/gpu/collect.py RESULTS_DIR ARCHIVE_DIR...

ARCHIVE_DIR: an unpacked step archive (its builds/, frame/ or ncu/ folder).
Writes RESULTS_DIR/builds.csv, frame_1080p.csv (per config and pass: the
median over frames of each frame's median GPU ms; refit and partial leave
out frame 0, their full build) and ncu_simt.csv (per kernel: Nsight
Compute's threads per executed instruction, /32 = SIMT efficiency).
"""
import csv, glob, json, os, statistics, sys
from collections import defaultdict

out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def timing_table(folder, name):
    rows = []
    for stats in sorted(glob.glob(os.path.join(folder, "*.gpu_stats.json"))):
        s = json.load(open(stats))
        config = os.path.basename(stats).split(".")[0]
        frames = s["frames"]
        steady = [f for f in frames if not (f["frame"] == frames[0]["frame"] and len(frames) > 2)]
        per_pass = defaultdict(list)
        for f in steady:
            for p, t in f["gpu_ms"].items():
                per_pass[p].append(t["median_ms"])
        f0 = steady[-1]
        for p, v in sorted(per_pass.items()):
            rows.append({"config": config, "pass": p, "ms": round(statistics.median(v), 4), "frames": len(v),
                         "clusters": f0["clusters"], "triangles": f0["triangles"],
                         "rebuilt_clusters": f0["rebuilt_clusters"], "blas_bytes": f0["blas_bytes"],
                         "blas_memory_bytes": f0["blas_memory_bytes"],
                         "blas_enqueue_ms": round(f0.get("blas_enqueue_ms", 0.0), 3),
                         "device": s["device"], "version": s["version"], "repeat": s["repeat"]})
    if rows:
        with open(os.path.join(out, name), "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()))
            w.writeheader()
            w.writerows(rows)
        print(f"{name}: {len(rows)} rows")


def ncu_table(folder):
    path = os.path.join(folder, "ncu.csv")
    rows = list(csv.reader(open(path)))
    hdr = rows[0]
    k, r, d = (hdr.index(c) for c in ("Kernel Name", "smsp__thread_inst_executed_per_inst_executed.ratio",
                                      "gpu__time_duration.sum"))
    agg = defaultdict(list)
    for row in rows[2:]:
        if len(row) > r and row[r]:
            name = row[k].split("(")[0].replace("void ", "").replace("accretion::<unnamed>::", "")
            agg[name].append((float(row[r]), float(row[d])))
    with open(os.path.join(out, "ncu_simt.csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["kernel", "launches", "threads_per_instruction", "simt_efficiency", "mean_us"])
        for name, v in agg.items():
            t = statistics.mean(a for a, _ in v)
            w.writerow([name, len(v), round(t, 3), round(t / 32, 4), round(statistics.mean(b for _, b in v), 2)])
    print(f"ncu_simt.csv: {len(agg)} kernels")


for a in sys.argv[2:]:
    if os.path.isdir(os.path.join(a, "builds")):
        timing_table(os.path.join(a, "builds"), "builds.csv")
    if os.path.isdir(os.path.join(a, "frame")):
        timing_table(os.path.join(a, "frame"), "frame_1080p.csv")
    if os.path.isdir(os.path.join(a, "ncu")):
        ncu_table(os.path.join(a, "ncu"))
