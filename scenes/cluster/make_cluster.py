#!/usr/bin/env python3
"""Writes cluster_150k's particle buffers: a flattened, differentially
rotating star cluster of 150K emitters, not a disk (an oblate Plummer
sphere, 5:1, truncated at 5 scale lengths), as the engine's raw 32-byte
records (float3 position, float radius, float3 emission, float opacity;
little-endian), one file per frame in scenes/cluster/frames/c.NNNN.bin.
Deterministic: re-running gives the same bytes. Files that exist with the
right size are kept.
  python3 scenes/cluster/make_cluster.py [FRAMES] [COUNT]   (24, 150000)"""
import array
import math
import random
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
FRAMES = int(sys.argv[1]) if len(sys.argv) > 1 else 24
COUNT = int(sys.argv[2]) if len(sys.argv) > 2 else 150000
SCALE, FLATTEN, OMEGA, DT = 2.5, 0.2, 0.35, 0.05


def particles(rng):
    out = []
    for _ in range(COUNT):
        while True:  # Plummer radius, truncated at 5 scale lengths
            u = rng.random()
            r = SCALE / math.sqrt(max(u, 1e-12) ** (-2.0 / 3.0) - 1.0) if u < 1.0 else 0.0
            if r < 5.0 * SCALE:
                break
        z = rng.uniform(-1.0, 1.0)
        phi = rng.uniform(0.0, 2.0 * math.pi)
        s = math.sqrt(1.0 - z * z)
        x, y, w = r * s * math.cos(phi), FLATTEN * r * z, r * s * math.sin(phi)
        temperature = rng.lognormvariate(0.0, 0.5)  # a spread of colours and powers
        hot = rng.random() < 0.05
        power = (20.0 if hot else 1.0) * temperature ** 2 * 0.02
        colour = (min(1.0, 0.6 + 0.4 * temperature), 0.8, min(1.5, 0.4 + 0.6 * temperature))
        radius = 0.02 * (0.5 + rng.random())
        out.append((x, y, w, radius, tuple(power * c for c in colour)))
    return out


def main():
    frames = HERE / "frames"
    frames.mkdir(exist_ok=True)
    base = particles(random.Random(150))
    for f in range(FRAMES):
        path = frames / f"c.{f:04d}.bin"
        if path.exists() and path.stat().st_size == 32 * COUNT:
            continue
        a = array.array("f")
        t = f * DT
        for x, y, w, radius, (er, eg, eb) in base:
            R = math.hypot(x, w)
            angle = OMEGA * t / (1.0 + (R / SCALE) ** 2) ** 0.75  # differential rotation about y
            c, s = math.cos(angle), math.sin(angle)
            a.extend((c * x - s * w, y, s * x + c * w, radius, er, eg, eb, 1.0))
        if sys.byteorder != "little":
            a.byteswap()
        path.write_bytes(a.tobytes())


if __name__ == "__main__":
    main()
