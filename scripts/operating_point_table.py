#!/usr/bin/env python3
"""The table of bench/operating_point.sh: one row per configuration from its
bias JSON (relMSE with its standard error over the seeds where the run
recorded one, with every light visible, visibility's share, energy
loss and the bias the seeds could see, reuse kept and why refused)."""
import json
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
print("| configuration | relMSE | every light visible | visibility share | energy loss | detectable | temporal kept | spatial kept (other particle) |")
print("|---|---|---|---|---|---|---|---|")
for f in sorted(out.glob("*.json"), key=lambda p: p.stat().st_mtime):
    j = json.loads(f.read_text())
    if j.get("command") != "bias":
        continue
    r = j["rows"][0]
    reuse = next(iter(j.get("reuse", {}).values()), {})

    def kept(p):
        c = reuse.get(p)
        if not c or not c["offered"]:
            return "-"
        s = f"{100 * c['accepted'] / c['offered']:.0f}%"
        if p == "spatialResampling" and c["accepted"]:
            s += f" ({100 * c['outcomes']['other_particle'] / c['accepted']:.0f}%)"
        return s

    se = r.get("rel_mse_stderr")
    rel = f"{r['rel_mse']:.3g}" + (f" +- {se:.2g}" if isinstance(se, (int, float)) and se == se else "")
    print(f"| {f.stem} | {rel} | {r['rel_mse_unshadowed']:.3g} | {r['visibility_share_pct']:.0f}% | "
          f"{r['energy_loss_pct']:+.1f}% | {r['detectable_bias_pct']:.2g}% | {kept('temporalResampling')} | {kept('spatialResampling')} |")
