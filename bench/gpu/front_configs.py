#!/usr/bin/env python3
"""The configurations `accretion tune` put on its Pareto front, as lines for
bench/gpu/run.sh's front step ("name  -D overrides...", on
scenes/disk_100k.toml), each timed as tune priced it (the twin draws
candidates from the CPU's light tree, tiles and ReGIR excepted).
Usage: front_configs.py OUT.txt TUNE.json..."""
import json
import sys


def main():
    out, tunes = sys.argv[1], sys.argv[2:]
    lines = ["# The Pareto fronts of `accretion tune` (bench/gpu/front_configs.py), timed by run.sh's front step."]
    for path in tunes:
        j = json.load(open(path))
        scene_defines = [d for d in j["defines"] if not d.startswith("gpu.coefficients")]
        geometry = None
        # The chosen geometry's defines: those of the recommendation (every front point shares them).
        if j.get("recommended"):
            geometry = [d for d in j["recommended"]["defines"] if d.startswith(("geometry.", "gpu.omm"))]
        tag = path.split("/")[-1].split(".")[0]
        for k, row in enumerate(r for r in j["lighting"] if r["front"]):
            lighting = row["lighting"].split()
            src = lighting[0]
            defines = list(scene_defines) + (geometry or [])
            m = lighting[1].split("=")[1]
            nb, it = lighting[2].split("=")[1].split("x")
            bc = lighting[3].replace("+vis", "")
            vis = "+vis" in lighting[3]
            scale = lighting[4].rstrip("x")
            defines += [f"render.source={src}", f"render.candidates={m}", f"restir.spatial_neighbours={nb}",
                        f"restir.spatial_iterations={it}", f"restir.bias_correction={bc}",
                        f"restir.visibility_reuse={'true' if vis else 'false'}", f"restir.resolution_scale={scale}"]
            name = f"{tag}_f{k}"
            lines.append(f"{name:40} " + " ".join(f"-D {d}" for d in defines) + f"   # {row['lighting']}")
    open(out, "w").write("\n".join(lines) + "\n")
    print(f"{out}: {len(lines) - 1} configurations")


if __name__ == "__main__":
    main()
