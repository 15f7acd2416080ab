#!/usr/bin/env python3
"""The warps' stall reasons of Nsight Compute raw pages (run.sh
split_stalls: `ncu --csv --page raw`), one launch a file: per file its
duration, achieved occupancy, issue rate and each stall reason's warps per
issued instruction (the reasons above 0.1 in some file).
  python3 bench/gpu/ncu_stalls.py NAME.raw.csv... > bench/gpu/results/split_stalls/stalls.csv"""
import csv
import pathlib
import sys

keep = {"gpu__time_duration.sum": "ms", "sm__warps_active.avg.pct_of_peak_sustained_active": "occupancy_pct",
        "smsp__inst_executed.sum": "warp_instructions", "smsp__issue_active.avg.per_cycle_active": "issue_per_cycle"}
prefix, suffix = "smsp__average_warps_issue_stalled_", "_per_issue_active.ratio"
rows = []
for path in sys.argv[1:]:
    header, units, values = list(csv.reader(open(path)))[:3]
    row = {"launch": pathlib.Path(path).name.split(".")[0]}
    for name, value in zip(header, values):
        if name in keep:
            row[keep[name]] = value.replace(",", "")
        elif name.startswith(prefix) and name.endswith(suffix):
            row["stall_" + name[len(prefix):-len(suffix)]] = value.replace(",", "")
    rows.append(row)
stalls = sorted({k for r in rows for k in r if k.startswith("stall_") and max(float(x.get(k, 0) or 0) for x in rows) > 0.1})
columns = ["launch"] + [c for c in keep.values() if any(c in r for r in rows)] + stalls
out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(columns)
for r in rows:
    out.writerow([r.get(c, "") for c in columns])
