#!/usr/bin/env python3
"""The table of bench/operating_point.sh: one row per configuration from its
bias JSON (relMSE with its standard error over the seeds where the run
recorded one; the share of it that persists over the seeds, the per-pixel
bias, where the run recorded it; with every light visible, visibility's
share, energy loss and the bias the seeds could see, reuse kept and why
refused), and the references' floor of one value a particle."""
import json
import pathlib
import sys

out = pathlib.Path(sys.argv[1])
print("| configuration | relMSE | persistent | every light visible | visibility share | energy loss | detectable | temporal kept | spatial kept (other particle) |")
print("|---|---|---|---|---|---|---|---|---|")
floor = None
for f in sorted(out.glob("*.json"), key=lambda p: p.stat().st_mtime):
    j = json.loads(f.read_text())
    if j.get("command") != "bias":
        continue
    r = j["rows"][0]
    floor = j.get("particle_mean_floor") or floor
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
    persistent = r.get("rel_mse_persistent")
    persistent = f"{100 * persistent / r['rel_mse']:.0f}%" if persistent is not None and r["rel_mse"] > 0 else "-"
    unshadowed = r.get("rel_mse_unshadowed")
    unshadowed = f"{unshadowed:.3g}" if isinstance(unshadowed, (int, float)) and unshadowed == unshadowed else "-"
    share = r.get("visibility_share_pct")
    share = f"{share:.0f}%" if isinstance(share, (int, float)) and share == share else "-"
    print(f"| {f.stem} | {rel} | {persistent} | {unshadowed} | {share} | "
          f"{r['energy_loss_pct']:+.1f}% | {r['detectable_bias_pct']:.2g}% | {kept('temporalResampling')} | {kept('spatialResampling')} |")
if floor:
    print(f"\nOne value a particle (each pixel its particle's mean reference Lr): relMSE floor {floor['rel_mse']:.3g}, "
          f"{floor['particles']} particles, a median {floor['median_pixels']:g} pixels each.")
