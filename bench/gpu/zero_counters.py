#!/usr/bin/env python3
"""Copies counter CSVs into FOLDER with the named counters set to 0: a fit
without them over the same counts (designs_fit.sh's DROP, the control of a
new counter). A file's copy keeps its name.
  python3 bench/gpu/zero_counters.py "node_visits warp_node_visits" FOLDER counters.csv..."""
import csv
import pathlib
import sys

names, folder = sys.argv[1].split(), pathlib.Path(sys.argv[2])
folder.mkdir(parents=True, exist_ok=True)
for f in map(pathlib.Path, sys.argv[3:]):
    rows = list(csv.reader(f.open()))
    columns = [rows[0].index(n) for n in names if n in rows[0]]
    for row in rows[1:]:
        for c in columns:
            row[c] = "0"
    with (folder / f.name).open("w") as out:
        csv.writer(out, lineterminator="\n").writerows(rows)
