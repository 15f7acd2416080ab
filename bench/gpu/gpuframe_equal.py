#!/usr/bin/env python3
"""Whether two .gpuframe files hold the same frame: the same size, camera and
planes byte for byte (the image, AOVs and counts). The metadata is not
compared: it records the run (its time, the commit, the output path).
    gpuframe_equal.py A.gpuframe B.gpuframe     exit 0 equal, 1 different"""
import json
import struct
import sys


def read(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"ACCGPUF1":
        sys.exit(f"{path}: not an accretion-optix frame")
    (n,) = struct.unpack_from("<Q", data, 8)
    header = json.loads(data[16:16 + n])
    header.pop("metadata", None)
    return header, data[16 + n:]


a, b = read(sys.argv[1]), read(sys.argv[2])
if a[0] != b[0]:
    print(f"headers differ: {a[0]} / {b[0]}")
    sys.exit(1)
if a[1] != b[1]:
    diff = sum(x != y for x, y in zip(a[1], b[1])) + abs(len(a[1]) - len(b[1]))
    print(f"planes differ in {diff} of {len(a[1])} bytes")
    sys.exit(1)
