#!/usr/bin/env python3
"""Each pass's median over separate runs of the twin (bench/gpu/retime_fit.sh).

    python3 bench/gpu/replicate_median.py RETIMED_DIR MEDIANS.csv REPLICATES.csv

RETIMED_DIR holds run<N>/<list>/<config>.timings.csv. MEDIANS.csv is
calibrate's timings CSV (config,pass,ms: the median over the runs);
REPLICATES.csv has every run's ms and the spread (max / min - 1). Prints,
per pass, the median and worst spread.
"""
import csv
import glob
import os
import statistics
import sys


def main(root, medians_path, replicates_path):
    runs = sorted(d for d in glob.glob(os.path.join(root, "run*")) if os.path.isdir(d))
    if not runs:
        sys.exit(f"{root}: no run<N>/ folders")
    times = {}  # (config, pass) -> [ms of each run]
    for k, run in enumerate(runs):
        for path in glob.glob(os.path.join(run, "*", "*.timings.csv")):
            with open(path, newline="") as f:
                for row in csv.DictReader(f):
                    times.setdefault((row["config"], row["pass"]), [None] * len(runs))[k] = float(row["ms"])
    incomplete = sorted(key for key, v in times.items() if None in v)
    if incomplete:
        sys.exit(f"{len(incomplete)} passes lack a run, e.g. {incomplete[0]}")
    keys = sorted(times)
    with open(medians_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "pass", "ms"])
        for key in keys:
            w.writerow([*key, f"{statistics.median(times[key]):.6f}"])
    spread = {key: max(v) / min(v) - 1.0 if min(v) > 0 else 0.0 for key, v in times.items()}
    with open(replicates_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "pass"] + [f"ms_run{k + 1}" for k in range(len(runs))] + ["max_over_min_minus_1"])
        for key in keys:
            w.writerow([*key] + [f"{t:.6f}" for t in times[key]] + [f"{spread[key]:.4f}"])
    print(f"{len(runs)} runs, {len({c for c, _ in keys})} configurations")
    print(f"{'pass':<20} {'median spread':>14} {'worst':>8}  worst configuration")
    for p in sorted({p for _, p in keys}):
        s = {c: spread[(c, q)] for c, q in keys if q == p}
        worst = max(s, key=s.get)
        print(f"{p:<20} {100 * statistics.median(s.values()):>13.1f}% {100 * s[worst]:>7.1f}%  {worst}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
