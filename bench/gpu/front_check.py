#!/usr/bin/env python3
"""Predicted against measured GPU ms for the configurations of
bench/gpu/front.txt: `accretion cost` of each (frame 1 after one history
frame, as the twin's timed frame) priced with COEFFICIENTS, against the
twin's timings (bench/gpu/run.sh front). Per configuration the frame's
total and each pass; writes OUT.csv.
Usage: front_check.py OUT.csv TIMINGS_DIR COEFFICIENTS.json"""
import csv
import json
import pathlib
import shlex
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent.parent
BIN = ROOT / "build" / "accretion"


def main():
    out, timings_dir, coefficients = sys.argv[1], pathlib.Path(sys.argv[2]), sys.argv[3]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for line in (ROOT / "bench" / "gpu" / "front.txt").read_text().splitlines():
            line = line.split("#")[0].strip()
            if not line:
                continue
            name, *args = shlex.split(line)
            timings = timings_dir / f"{name}.timings.csv"
            if not timings.exists():
                print(f"{name}: no timings", file=sys.stderr)
                continue
            measured = {r["pass"]: float(r["ms"]) for r in csv.DictReader(open(timings))}
            prefix = pathlib.Path(tmp) / name
            subprocess.run([str(BIN), "cost", str(ROOT / "scenes" / "disk_100k.toml"), "-D", "render.estimator=restir", *args,
                            "-D", f"gpu.coefficients={coefficients}", "--frames", "1:2", "--history", "1", "--overhead", "0",
                            "--cluster-sizes", "", "--omm-levels", "", "--ser-keys", "hit", "-q", "-o", f"{prefix}.json"],
                           check=True, stdout=subprocess.DEVNULL)
            predicted = {}
            for p in json.load(open(f"{prefix}.json"))["passes"]:
                family = p["pass"].split("[")[0]
                predicted[family] = predicted.get(family, 0.0) + p["predicted_ms"]
            for p in sorted(measured) + ["frame"]:
                m = sum(measured.values()) if p == "frame" else measured[p]
                q = sum(v for k, v in predicted.items() if k in measured) if p == "frame" else predicted.get(p, 0.0)
                rows.append({"config": name, "pass": p, "measured_ms": round(m, 4), "predicted_ms": round(q, 4),
                             "error_pct": round(100.0 * (q - m) / m, 1) if m > 0 else ""})
            print(f"{name}: measured {sum(measured.values()):.3f} ms, predicted "
                  f"{sum(v for k, v in predicted.items() if k in measured):.3f} ms", file=sys.stderr)
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=["config", "pass", "measured_ms", "predicted_ms", "error_pct"])
        w.writeheader()
        w.writerows(rows)


if __name__ == "__main__":
    main()
