#!/usr/bin/env python3
"""SIMT efficiency per pass: the model's (`accretion cost` JSON of a frame)
beside Nsight Compute's (average active threads per executed instruction / 32,
the ncu.csv of bench/gpu/run.sh's ncu step, the same frame).

    python3 bench/gpu/simt_table.py COST_JSON NCU_CSV OUT_CSV [FRAME_INDEX]

The twin's OptiX launches alternate traceGBuffer and traceShadowRays (one of
each per frame, in that order); FRAME_INDEX (default: the last frame
profiled) picks the frame whose launches are reported."""
import csv, json, sys
import pathlib
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scripts"))
from pass_names import PASS  # noqa: E402

cost_json, ncu_csv, out = sys.argv[1:4]
model = {}
for p in json.load(open(cost_json))["passes"]:
    s = p["simt_efficiency"]
    b, l = s["branch"], s["loop"]
    steps = b["steps"] + l["steps"]
    model[p["pass"]] = (b["efficiency"], l["efficiency"], (b["lane_work"] + l["lane_work"]) / (32 * steps) if steps else 0.0)

rows = list(csv.reader(open(ncu_csv)))
h = rows[0]
name, ratio, time = h.index("Kernel Name"), h.index("smsp__thread_inst_executed_per_inst_executed.ratio"), h.index("gpu__time_duration.sum")
kernels = {"expandBillboards": PASS.buildClusters, "generateCandidates": PASS.generateCandidates,
           "temporalResampling": PASS.temporalResampling, "spatialResampling": PASS.spatialResampling}
frames, launches = [], 0
for r in rows[2:]:
    k = r[name]
    if "expandBillboards" in k:
        frames.append({})
    if not frames:
        continue
    if k == "optixLaunch":
        p = PASS.traceGBuffer if launches % 2 == 0 else PASS.traceShadowRays
        launches += 1
    else:
        p = next((v for key, v in kernels.items() if key in k), None)
        if p is None:
            continue
    label = "expandBillboards" if "expandBillboards" in k else p
    frames[-1][label] = (float(r[ratio]) / 32.0, float(r[time]))
frame = frames[int(sys.argv[4]) if len(sys.argv) > 4 else -1]
with open(out, "w", newline="") as fh:
    w = csv.writer(fh)
    w.writerow(["kernel", "model_pass", "model_branch", "model_loop", "model_combined", "ncu_simt", "ncu_us"])
    for label, (simt, us) in frame.items():
        p = PASS.buildClusters if label == "expandBillboards" else label
        m = model.get(p, (0.0, 0.0, 0.0))
        w.writerow([label, p] + [f"{x:.3f}" for x in m] + [f"{simt:.3f}", f"{us:.1f}"])
print(open(out).read())
