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

# Class 10: GPU frames (.gpuframe, docs/gpu-frame-format.md) whose header
# says what the file cannot hold or what no camera is.
import json

def gpuframe(header, payload=None, w=2, h=1, planes=("L", "Le", "Lr", "normal", "depth", "particle")):
    sizes = {"L": 12, "Le": 12, "Lr": 12, "normal": 12, "depth": 4, "particle": 4, "Lr_stderr": 12, "spp": 4, "rejected": 4}
    base = {"width": w, "height": h, "frame": 0,
            "camera": {"eye": [0, 1, 5], "forward": [0, 0, -1], "right": [1, 0, 0], "up": [0, 1, 0],
                       "tan_half_fov": 0.4, "jitter": [0, 0]},
            "metadata": {"frame": "0"}, "planes": list(planes)}
    base.update(header)
    text = json.dumps(base).encode()
    if payload is None:
        payload = b"".join(b"\0" * (sizes[p] * 2) for p in planes)
    return b"ACCGPUF1" + struct.pack("<Q", len(text)) + text + payload

write("gpu_ok.gpuframe", gpuframe({}))
write("gpu_huge.gpuframe", gpuframe({"width": 16384, "height": 16384}))
write("gpu_frame_negative.gpuframe", gpuframe({"frame": -1}))
write("gpu_zero_camera.gpuframe", gpuframe({"camera": {"eye": [0, 0, 0], "forward": [0, 0, 0], "right": [0, 0, 0],
                                                       "up": [0, 0, 0], "tan_half_fov": 0, "jitter": [0, 0]}}))
write("gpu_frame_disagrees.gpuframe", gpuframe({"frame": 3}))
# A plane list that names a plane twice, or one no frame has: refused by name.
write("gpu_plane_twice.gpuframe", gpuframe({}, planes=("Lr", "Lr")))
write("gpu_plane_unknown.gpuframe", gpuframe({}, payload=b"\0" * 48, planes=("Lr", "albedo")))
os.makedirs("gpu_a", exist_ok=True)
os.makedirs("gpu_b", exist_ok=True)
write("gpu_a/frame.gpuframe", gpuframe({}))
write("gpu_b/frame.gpuframe", gpuframe({}))

# Class 10: an EXR whose data window claims 100000 x 100000 pixels in a file of a few hundred bytes.
exr = bytearray(open("half.exr", "rb").read())
at = exr.index(b"dataWindow\0box2i\0") + len(b"dataWindow\0box2i\0") + 4
exr[at:at + 16] = struct.pack("<4i", 0, 0, 99999, 99999)
at = exr.index(b"displayWindow\0box2i\0") + len(b"displayWindow\0box2i\0") + 4
exr[at:at + 16] = struct.pack("<4i", 0, 0, 99999, 99999)
write("huge_window.exr", bytes(exr))

# Class 10: camera files with a BOM and a trailing comma, a number no double holds.
write("cams_bom_comma.json", b'\xef\xbb\xbf{"frames": [{"frame": 0, "eye": [0, 1, 5], "look_at": [0, 0, 0],}]}\n')
write("cams_overflow.json", '{"frames": [\n  {"frame": 0, "eye": [0, 1, 1e400], "look_at": [0, 0, 0]}\n]}\n')
write("cams_far.csv", "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z\n0,0,1e300,5e300,0,0,0\n")
write("cams_units.csv", "# jitter_units = NDCs\nframe,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z\n0,0,1,5,0,0,0\n")
# A camera file of frames 4..30: tune checks the frames it renders (its
# history and the measured frame), not the scene's first frame.
write("cams_4_30.csv", "frame,eye_x,eye_y,eye_z,look_at_x,look_at_y,look_at_z\n" +
      "".join(f"{k},0,1,5,0,0,0\n" for k in range(4, 31)))
write("coef_unknown.json", '{"coefficients_ns": {"threads": 1, "warp_steps": 1, "rays": 1, "blas_entries": 1, '
                           '"any_hits": 1, "bytes": 1, "blas_entires": 1}}\n')
shutil.copy("half.exr", "seqimg.0000.exr")
shutil.copy("half.exr", "seqimg.0001.exr")

# Class 11: references for bias and compare's view checks: one of ok.toml's
# frame 0, one at another field of view, one with a NaN, one without metadata.
subprocess.run([acc, "render", "ok.toml", "--quiet", "--estimator", "exact", "-o", "ref_ok.exr"], check=True,
               stdout=subprocess.DEVNULL)
subprocess.run([acc, "render", "ok.toml", "--quiet", "--estimator", "exact", "-D", "camera.fov=30", "-o", "ref_fov.exr"],
               check=True, stdout=subprocess.DEVNULL)
for f in os.listdir("."):
    if (f.startswith("ref_ok") or f.startswith("ref_fov")) and not f.endswith(".exr"):
        os.remove(f)
subprocess.run(["oiiotool", "--pattern", "constant:color=-1,0.5,0.5", "32x16", "3", "--powc", "0.5,1,1",
                "--chnames", "Lr.R,Lr.G,Lr.B", "-d", "float", "-o", "ref_nan.exr"], check=True)
subprocess.run(["oiiotool", "--pattern", "constant:color=0.5,0.5,0.5", "32x16", "3",
                "--chnames", "Lr.R,Lr.G,Lr.B", "-d", "float", "-o", "ref_plain.exr"], check=True)

# Class 12: the summary of another batch where this one would write its own.
os.makedirs("batch_other", exist_ok=True)
write("batch_other/batch.json", '{"version": "x", "jobs": [{"name": "other_job", "outcome": "ok"}]}\n')

# Class 10: a D3D projection offset by the usual TAA formula (_31 += 2 jx / W)
# with the engine's jx given as the jitter: the samples lie at -jx.
f = 2.414213562373095
proj = [f / 2, 0, 0, 0, 0, f, 0, 0, 2 * 0.25 / 32, 0, 1.0001, 1, 0, 0, -0.010001, 0]
write("cams_taa_sign.json", json.dumps({"convention": "d3d", "frames": [
    {"frame": 0, "view": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 10, 1], "projection": proj, "jitter": [0.25, 0]}]}) + "\n")
