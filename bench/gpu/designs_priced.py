#!/usr/bin/env python3
"""The cost model's price of each design against the twin: `accretion cost`
of every bench/gpu/designs.txt configuration (its JSON per configuration,
priced with the committed H100 calibration, which saw none of them) beside
the H100's measured ms of results/designs.csv, per pass and for the frame.
  python3 bench/gpu/designs_priced.py COST_DIR > bench/gpu/results/designs_priced.csv
COST_DIR holds cost_<config>.json (bench/gpu/designs_cost.sh writes them)."""
import csv
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).parent))
import designs_timings  # noqa: E402

folder = pathlib.Path(sys.argv[1])
measured = designs_timings.h100_timings()
out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(["config", "pass", "predicted_ms", "measured_ms", "relative_error"])
for f in sorted(folder.glob("cost_*.json")):
    j = json.loads(f.read_text())
    config = j["config"]
    if config not in measured:
        continue
    m = measured[config]
    predicted = {p["pass"]: p["predicted_ms"] for p in j["passes"] if p["pass"] in m}
    for p, ms in predicted.items():
        out.writerow([config, p, f"{ms:.4f}", f"{m[p]:.4f}", f"{ms / m[p] - 1:+.3f}"])
    frame_p, frame_m = sum(predicted.values()), sum(v for k, v in m.items() if k in predicted)
    out.writerow([config, "frame", f"{frame_p:.4f}", f"{frame_m:.4f}", f"{frame_p / frame_m - 1:+.3f}"])
