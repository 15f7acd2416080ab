#!/usr/bin/env python3
"""The restir configuration table for the GPU team.

For each scene: every candidate source (uniform, power, tree, tiles, regir)
x bias correction (none, basic, pairwise) x visibility reuse (off, on), and
uniform Monte Carlo as the baseline, measured by `accretion bias` over
--seeds seeds at frame 1 after one history frame, 320x180:

- relMSE of one frame (mean over seeds, less the reference's noise), the
  CPU seconds of that frame, and the equal-time gain over uniform Monte
  Carlo: uniform's relMSE x time is constant in its samples, so at the
  restir frame's time t uniform's relMSE is relMSE_u t_u / t; the gain is
  that over restir's relMSE (>1: restir is better at equal time);
- the bias: mean signed error over the seeds, its z and the energy loss;
- the GPU time `accretion cost` predicts with the cost model fitted to
  the team's H100 timings (bench/gpu/results/fit, the `selected` form):
  the whole frame, and its lighting passes alone (presampling, candidates,
  reuse, shadow rays: what the configuration changes). The presampling
  passes have no timings of their own and are priced with
  generateCandidates' coefficients (the costProxy column of `accretion passes`).

References: quickstart, exact; disk_100k, split with k = 256 at 1024 spp.
Writes out/restir_table/<scene>.{md,json} and, with --update-docs, the
table between the restir-table markers of docs/experiments.md. Run from anywhere; needs
build/accretion (Release).
"""
import argparse
import json
import pathlib
import subprocess
import sys

from pass_names import PASS

ROOT = pathlib.Path(__file__).resolve().parent.parent
BIN = ROOT / "build" / "accretion"
SOURCES = ["uniform", "power", "tree", "tiles", "regir"]
CORRECTIONS = ["none", "basic", "pairwise"]
SMALL = ["-D", "camera.width=320", "-D", "camera.height=180"]
COEFFICIENTS = ROOT / "bench" / "gpu" / "results" / "fit" / "coefficients_selected.json"
LIGHTING = (PASS.presampleLightTiles, PASS.presampleRegirGrid, PASS.generateCandidates, PASS.temporalResampling,
            PASS.spatialResampling, PASS.traceShadowRays)
BEGIN, END = "<!-- restir-table:begin -->", "<!-- restir-table:end -->"


def run(args, quiet=True):
    cmd = [str(BIN)] + [str(a) for a in args] + (["--quiet"] if quiet else [])
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL if quiet else None)


def configs():
    """(spec, source, correction, visibility reuse, -D settings) per restir row."""
    for src in SOURCES:
        for bc in CORRECTIONS:
            for vis in (False, True):
                # basic with visibility reuse is unbiased only when it tests V
                # at the neighbours (basic+vis: restir.basic_visibility).
                opt = "basic+vis" if (bc == "basic" and vis) else bc
                spec = f"restir:{opt}:{src}" + (":restir.visibility_reuse=true" if vis else "")
                defines = ["-D", 'render.estimator="restir"', "-D", f'render.source="{src}"',
                           "-D", f'restir.bias_correction="{bc}"', "-D", f"restir.visibility_reuse={str(vis).lower()}",
                           "-D", f"restir.basic_visibility={str(bc == 'basic' and vis).lower()}"]
                yield spec, src, bc, vis, defines


def reference(scene, out):
    ref = out / f"{scene}.ref.exr"
    if ref.exists():
        return ref
    est = ["--estimator", "exact"] if scene == "quickstart" else \
          ["--estimator", "split", "-D", "render.near_lights=256", "--spp", "1024"]
    run(["render", ROOT / "scenes" / f"{scene}.toml", *SMALL, *est, "--frames", "1:2", "-o", ref])
    return ref


def measure(scene, seeds, out):
    ref = reference(scene, out)
    scene_file = ROOT / "scenes" / f"{scene}.toml"
    rows = list(configs())
    baseline = "uniform:render.samples=16"
    specs = [baseline] + [r[0] for r in rows]
    prefix = out / f"{scene}.bias"
    run(["bias", scene_file, *SMALL, "--reference", ref, "--estimators", ",".join(specs), "--frame", 1,
         "--history", 1, "--seeds", seeds, "-o", prefix])
    bias = {r["estimator"]: r for r in json.loads(pathlib.Path(f"{prefix}.json").read_text())["rows"]}
    u = bias[baseline]
    table = []
    for spec, src, bc, vis, defines in rows:
        b = bias[spec]
        cost = out / f"{scene}.cost.{spec.replace(':', '_').replace('=', '_')}.json"
        run(["cost", scene_file, *SMALL, *defines, "-D", f'gpu.coefficients="{COEFFICIENTS}"', "--frames", 1,
             "--history", 1, "--overhead", 0, "--cluster-sizes", "", "--omm-levels", "", "-o", cost])
        c = json.loads(cost.read_text())
        t = b["seconds_per_frame"]
        uniform_at_t = u["rel_mse"] * u["seconds_per_frame"] / t
        table.append({"spec": spec, "source": src, "correction": bc, "visibility_reuse": vis,
                      "rel_mse": b["rel_mse"], "cpu_ms": 1e3 * t, "gain_vs_uniform": uniform_at_t / b["rel_mse"],
                      "t": b["t"], "energy_loss_pct": b["energy_loss_pct"],
                      "energy_loss_stderr_pct": b["energy_loss_stderr_pct"], "biased": b["biased"],
                      "gpu_ms": c["predicted_ms"],
                      "gpu_lighting_ms": sum(p["predicted_ms"] for p in c["passes"] if p["pass"] in LIGHTING),
                      "gpu_presample_ms": sum(p["predicted_ms"] for p in c["passes"]
                                              if p["pass"] in ("presampleLightTiles", "presampleRegirGrid"))})
    return {"scene": scene, "seeds": seeds, "reference": str(ref), "uniform": u, "rows": table}


def markdown(m):
    u = m["uniform"]
    lines = [f"**{m['scene']}** (320x180, frame 1 after 1 history frame, {m['seeds']} seeds; uniform Monte Carlo at 16 spp: "
             f"relMSE {u['rel_mse']:.3g} in {1e3 * u['seconds_per_frame']:.0f} ms)", "",
             "| source | bias correction | vis. reuse | relMSE | CPU ms | gain vs uniform at equal time | bias t | energy loss % | GPU ms: frame / lighting / presampling |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in m["rows"]:
        corr = r["correction"] + ("+vis" if r["correction"] == "basic" and r["visibility_reuse"] else "")
        flag = " **biased**" if r["biased"] else ""
        lines.append(f"| {r['source']} | {corr} | {'on' if r['visibility_reuse'] else 'off'} | {r['rel_mse']:.3g} | "
                     f"{r['cpu_ms']:.0f} | {r['gain_vs_uniform']:.2f}x | {r['t']:.1f}{flag} | "
                     f"{r['energy_loss_pct']:.2f} +- {r['energy_loss_stderr_pct']:.2f} | "
                     f"{r['gpu_ms']:.2f} / {r['gpu_lighting_ms']:.3f} / {r['gpu_presample_ms']:.3f} |")
    unbiased = [r for r in m["rows"] if not r["biased"] and r["correction"] != "none"]
    if unbiased:
        best = max(unbiased, key=lambda r: r["gain_vs_uniform"])
        lines += ["", f"Best unbiased configuration at equal CPU time: `{best['spec']}`, "
                      f"{best['gain_vs_uniform']:.2f}x uniform Monte Carlo; predicted GPU lighting passes "
                      f"{best['gpu_lighting_ms']:.3f} ms of a {best['gpu_ms']:.2f} ms frame."]
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="quickstart,disk_100k")
    ap.add_argument("--seeds", type=int, default=64)
    ap.add_argument("--out", default=str(ROOT / "out" / "restir_table"))
    ap.add_argument("--update-docs", action="store_true")
    a = ap.parse_args()
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    version = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                             text=True).stdout.strip()
    parts = []
    for scene in a.scenes.split(","):
        m = measure(scene, a.seeds, out)
        m["commit"] = version
        (out / f"{scene}.json").write_text(json.dumps(m, indent=2))
        md = markdown(m)
        (out / f"{scene}.md").write_text(md)
        print(md)
        parts.append(md)
    if a.update_docs:
        readme = ROOT / "docs" / "experiments.md"
        text = readme.read_text()
        if BEGIN not in text or END not in text:
            sys.exit(f"{readme}: no {BEGIN} ... {END} markers")
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        body = f"\nMeasured at {version} by `scripts/restir_table.py --seeds {a.seeds}` on the 2-core VM.\n\n" + \
               "\n".join(parts)
        readme.write_text(head + BEGIN + body + END + tail)


if __name__ == "__main__":
    main()
