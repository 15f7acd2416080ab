#!/usr/bin/env python3
"""A pass's runs in a frame (spatialResampling, spatialResampling[2], ...)
summed into one row per configuration and pass: every numeric column added,
working_set_bytes the largest (the same data read again). For CSVs whose
other side names the pass once: the sweep's counters (sweep_cost.sh) and
its timings of the twin that times each run apart (run.sh sweep), whose
counters were summed so. Rows in the order first seen.
  python3 bench/gpu/sum_runs.py CSV... > SUMMED.csv"""
import csv
import re
import sys

rows, header = {}, None
for path in sys.argv[1:]:
    with open(path) as fh:
        r = csv.reader(fh)
        h = next(r)
        if header is None:
            header = h
        elif h != header:
            sys.exit(f"{path}: columns {h} differ from {header}")
        for row in r:
            key = (row[0], re.sub(r"\[\d+\]$", "", row[1]))
            vals = [float(x) for x in row[2:]]
            if key in rows:
                rows[key] = [max(a, b) if c == "working_set_bytes" else a + b for c, a, b in zip(header[2:], rows[key], vals)]
            else:
                rows[key] = vals
w = csv.writer(sys.stdout, lineterminator="\n")
w.writerow(header)
for (config, p), vals in rows.items():
    w.writerow([config, p] + [f"{v:.10g}" for v in vals])
