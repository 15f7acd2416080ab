#!/usr/bin/env python3
"""Writes the generated cases of this corpus (binary particle files, EXRs,
shards, deep TOML): `python3 make_cases.py BUILD/accretion` from this folder.
The text cases (.toml, .args, .cmd, .expected) are written by hand."""
import os, struct, subprocess, sys

acc = sys.argv[1] if len(sys.argv) > 1 else "../../build/accretion"

def write(name, data):
    with open(name, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())

def record(x, r=0.5, e=(1.0, 1.0, 1.0), a=1.0):
    return struct.pack("<8f", x, 0.0, 0.0, r, *e, a)

SEVEN = ["property float x", "property float y", "property float z", "property float radius",
         "property float emission_r", "property float emission_g", "property float emission_b"]

def ply(count, props, body, eol="\n", extra_lines=()):
    lines = ["ply", "format binary_little_endian 1.0", *extra_lines, f"element vertex {count}", *props, "end_header"]
    return (eol.join(lines) + eol).encode() + body

def seven(x):
    return struct.pack("<7f", x, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0)

# Class 7: PLY headers.
write("ply_short_count.ply", ply(2, SEVEN, seven(0) + seven(1) + seven(2)))
write("ply_unnamed.ply", ply(1, SEVEN + ["property float"], seven(0) + b"abcd"))
write("ply_duplicate.ply", ply(1, SEVEN + ["property float x"], seven(0) + b"abcd"))
write("ply_int_type.ply", ply(1, ["property int x"] + SEVEN[1:], seven(0)))
write("ply_list.ply", ply(1, SEVEN + ["property list uchar int idx"], seven(0)))
write("ply_raw_named.ply", record(0.0) * 2)
write("ply_huge_count.ply", ply(10**15, SEVEN, seven(0)))
write("ply_uchar_opacity.ply", ply(2, SEVEN + ["property uchar opacity"], seven(0) + b"\x40" + seven(1) + b"\xff"))
write("ply_crlf.ply", ply(2, SEVEN, seven(0) + seven(1), eol="\r\n"))
write("ply_comment_end_header.ply", ply(2, SEVEN, seven(0) + seven(1), extra_lines=["comment end_header is not here"]))
write("PARTS.PLY", ply(2, SEVEN, seven(0) + seven(1)))

# Class 8: {frame} sequences.
write("seq_count.0000.bin", record(0.0) * 3)
write("seq_count.0001.bin", record(0.0) * 4)
write("seq_missing.0000.bin", record(0.0) * 3)
write("seq_missing.0001.bin", record(0.0) * 3)
write("seq_bad.0000.bin", record(0.0) * 3)
write("seq_bad.0001.bin", (record(0.0) * 3)[:-5])
write("seq_neighbour.0000.bin", record(0.0) * 3)
write("seq_neighbour.0001.bin", record(0.0) * 5)

# Class 1: a raw particle file named like the preview of -o clash_particles.exr.
write("clash_particles.png", record(0.0) * 3)

# Class 6: nesting.
write("deep_header.toml", "[" + ".".join(["a"] * 50000) + "]\n")
write("deep_dotted_key.toml", "[render]\n" + ".".join(["k"] * 5000) + " = 1\n")
write("deep_array.toml", "[render]\nx = " + "[" * 5000 + "]" * 5000 + "\n")
write("deep_inline.toml", "[render]\nx = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n")
write("deep_jobs.toml", "[[" + ".".join(["job"] * 50000) + "]]\n")

# Class 9: images for compare.
subprocess.run(["oiiotool", "--pattern", "constant:color=0.5,0.5,0.5", "4x2", "3", "-d", "float", "-o", "half.exr"], check=True)
subprocess.run(["oiiotool", "--pattern", "fill:left=-1,0.5,0.5:right=1,0.5,0.5", "4x2", "3", "--powc", "0.5,1,1",
                "-d", "float", "-o", "some_nan.exr"], check=True)
subprocess.run(["oiiotool", "--pattern", "constant:color=-1,0.5,0.5", "4x2", "3", "--powc", "0.5,1,1",
                "-d", "float", "-o", "all_nan.exr"], check=True)
subprocess.run(["oiiotool", "half.exr", "-o", "half.png"], check=True)

# Class 1: two shards of one run, for merge.
for i in (0, 1):
    subprocess.run([acc, "render", "ok.toml", "--quiet", "--estimator", "uniform", "--spp", "16", "--shard", f"{i}/2",
                    "-o", "shard.exr"], check=True, stdout=subprocess.DEVNULL)
for f in os.listdir("."):
    if f.startswith("shard") and (f.endswith(".png") or f.endswith(".json") or f.endswith(".toml")):
        os.remove(f)

# Class 1: a device and a directory where the EXR would go, a link to an input.
for link, target in (("devnull.exr", "/dev/null"), ("link_to_scene.exr", "ok.toml")):
    if os.path.lexists(link):
        os.remove(link)
    os.symlink(target, link)
os.makedirs("adir.exr", exist_ok=True)
write("adir.exr/keep", "a directory named like an EXR\n")

# Class 1, other commands: a reference named like a bias map, a particle
# sequence where `particles --out .` would write, a scene named like an
# output of converge.
import shutil
shutil.copy("half.exr", "ref.power.exr")
shutil.copy("seq_missing.0000.bin", "selfseq.0000.bin")
shutil.copy("ok.toml", "conv.json")
