#!/usr/bin/env python3
"""Writes the particle files of the stress scenes (raw GPU records:
float3 position, float radius, float3 emission, float opacity; little-endian).
Deterministic: re-running gives the same bytes."""
import math
import random
import struct
from pathlib import Path

HERE = Path(__file__).resolve().parent


def write(name, particles):
    with open(HERE / name, "wb") as f:
        for (x, y, z), r, (er, eg, eb) in particles:
            f.write(struct.pack("<8f", x, y, z, r, er, eg, eb, 1.0))


def ring(rng, n, r_in, r_out, radius, emission, centre=(0.0, 0.0, 0.0), thickness=0.05):
    out = []
    for _ in range(n):
        r = math.sqrt(rng.uniform(r_in**2, r_out**2))
        t = rng.uniform(0.0, 2.0 * math.pi)
        y = rng.gauss(0.0, thickness)
        e = emission(rng)
        out.append(((centre[0] + r * math.cos(t), centre[1] + y, centre[2] + r * math.sin(t)), radius, (e, e, e)))
    return out


def main():
    rng = random.Random(6)
    # One particle: nothing lights it (i != j), only self-emission.
    write("one_particle.bin", [((0.0, 0.0, 0.0), 0.5, (1.0, 0.8, 0.6))])
    # Two particles, receiver and a small emitter 2 units away: Lr in closed form.
    write("two_particles.bin", [((0.0, 0.0, 0.0), 0.05, (0.0, 0.0, 0.0)), ((0.0, 0.3, -2.0), 0.01, (1.0, 2.0, 3.0))])
    # The same pair 1e5 units from the origin (float spacing there: 2^-7).
    far = (1.0e5, 1.0e5, 0.0)
    write("two_particles_far.bin", [((far[0], far[1], 0.0), 0.05, (0.0, 0.0, 0.0)),
                                    ((far[0], far[1] + 0.3, -2.0), 0.01, (1.0, 2.0, 3.0))])
    # Coincident particles: a ring plus triplets at exactly the same point
    # (same and different radii): distance 0 between emitter and receiver.
    parts = ring(rng, 300, 0.5, 2.0, 0.04, lambda g: g.uniform(0.2, 1.0))
    for k in range(6):
        p = parts[k * 7][0]
        for radius in (0.04, 0.04, 0.08):
            parts.append((p, radius, (1.0, 1.0, 1.0)))
    write("coincident.bin", parts)
    # Emission from 1e-20 to 1e20 (log-uniform), one particle at each end.
    parts = ring(rng, 400, 0.5, 2.0, 0.04, lambda g: 10.0 ** g.uniform(-20.0, 20.0))
    parts[0] = (parts[0][0], parts[0][1], (1e-20, 1e-20, 1e-20))
    parts[1] = (parts[1][0], parts[1][1], (1e20, 1e20, 1e20))
    write("emission_range.bin", parts)
    # Emission near the float maximum on small close particles: f I G
    # overflows float, so samples are Inf or NaN (render.nonfinite decides).
    parts = ring(rng, 200, 0.5, 2.0, 0.04, lambda g: 1.0)
    for k in range(0, 200, 20):
        parts[k] = (parts[k][0], parts[k][1], (3.0e38, 3.0e38, 3.0e38))
    write("emission_overflow.bin", parts)


if __name__ == "__main__":
    main()
