#!/usr/bin/env python3
"""The fit's timings after a change to the twin: one new run of the four
lists (bench/gpu/retime_fit.sh) against the committed per-pass medians.

    python3 bench/gpu/moved_passes.py RETIMED_DIR FIT_TIMINGS.csv OUT.csv RUN.csv [SPREAD]

Per pass, prints the ratio new / committed over the configurations (median,
10th and 90th percentile, extremes). A pass whose median ratio lies outside
1 +- SPREAD (default 0.015: almost three times the largest per-pass
median spread between the committed three runs, 0.55% for
temporalResampling in bench/gpu/results/replicates_h100.csv; builds, whose
time moves from one process to the next, never count) has moved: its rows in OUT.csv take the new run's time; every other
pass keeps its committed median. RUN.csv is the new run as it came
(config,pass,ms), kept beside the fit.
"""
import csv
import glob
import os
import statistics
import sys


def read(path):
    with open(path, newline="") as f:
        return {(r["config"], r["pass"]): float(r["ms"]) for r in csv.DictReader(f)}


def main(root, fit_path, out_path, run_path, spread=0.015):
    new = {}
    for path in glob.glob(os.path.join(root, "run*", "*", "*.timings.csv")):
        new.update(read(path))
    old = read(fit_path)
    missing = sorted(set(old) - set(new))
    if missing:
        sys.exit(f"{root}: {len(missing)} timed passes lack a new time, e.g. {missing[0]}")
    ratios = {}
    for key, ms in old.items():
        ratios.setdefault(key[1], []).append(new[key] / ms)
    moved = set()
    print(f"{'pass':<20} {'rows':>5} {'median':>7} {'p10':>6} {'p90':>6} {'min':>6} {'max':>6}  taken")
    for p, r in sorted(ratios.items()):
        r.sort()
        m = statistics.median(r)
        # A build's time moves from one process to the next (replicates_h100.csv): it never counts as moved.
        if abs(m - 1.0) > spread and p != "buildClusters":
            moved.add(p)
        print(f"{p:<20} {len(r):>5} {m:>7.3f} {r[len(r) // 10]:>6.3f} {r[9 * len(r) // 10]:>6.3f} {r[0]:>6.3f} {r[-1]:>6.3f}  "
              f"{'new run' if p in moved else 'committed median'}")
    with open(out_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "pass", "ms"])
        for key in old:
            w.writerow([key[0], key[1], f"{(new if key[1] in moved else old)[key]:.6f}"])
    with open(run_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["config", "pass", "ms"])
        for key in sorted(new):
            w.writerow([key[0], key[1], f"{new[key]:.6f}"])


if __name__ == "__main__":
    if len(sys.argv) not in (5, 6):
        sys.exit(__doc__)
    main(*sys.argv[1:5], *(float(a) for a in sys.argv[5:]))
