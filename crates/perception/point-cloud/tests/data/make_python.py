"""Writes the test files that come from an independent writer: Python's
struct module for PLY/PCD layouts our writer never produces, laspy (LAS)
and laspy + lazrs (LAZ). Run: python3 make_python.py (needs laspy, lazrs,
numpy). The expected coordinates are repeated in tests/io_external.rs."""
import struct

import laspy
import numpy as np

# --- PLY: every scalar type for x/y/z, a list in the vertex element, faces.
VERTS = [  # (red uchar, x double, y short, z int, list of ints, w float)
    (255, 1.5, -2, 100000, [1, 2, 3], 0.5),
    (0, -1e-3, 32767, -7, [], 1.0),
    (17, 123456.789, -32768, 0, [9], 2.0),
    (3, float("nan"), 5, 6, [4, 4], 3.0),
]
FACES = [[0, 1, 2], [1, 2, 3, 0]]


def ply(fmt, endian):
    head = (
        "ply\n"
        f"format {fmt} 1.0\n"
        "comment made by make_python.py\n"
        "obj_info no object\n"
        "element vertex 4\n"
        "property uchar red\n"
        "property double x\n"
        "property int16 y\n"
        "property int z\n"
        "property list uint8 int32 extra\n"
        "property float32 w\n"
        "element face 2\n"
        "property list uchar uint vertex_indices\n"
        "element empty 0\n"
        "property char nothing\n"
        "end_header\n"
    ).encode()
    if fmt == "ascii":
        body = ""
        for r, x, y, z, l, w in VERTS:
            body += f"{r} {x!r} {y} {z} {len(l)} {' '.join(map(str, l))} {w}\n".replace("  ", " ")
        for f in FACES:
            body += f"{len(f)} {' '.join(map(str, f))}\n"
        return head + body.encode()
    e = endian
    body = b""
    for r, x, y, z, l, w in VERTS:
        body += struct.pack(f"{e}BdhiB", r, x, y, z, len(l))
        body += struct.pack(f"{e}{len(l)}i", *l)
        body += struct.pack(f"{e}f", w)
    for f in FACES:
        body += struct.pack(f"{e}B{len(f)}I", len(f), *f)
    return head + body


open("python_mixed_ascii.ply", "wb").write(ply("ascii", ""))
open("python_mixed_le.ply", "wb").write(ply("binary_little_endian", "<"))
open("python_mixed_be.ply", "wb").write(ply("binary_big_endian", ">"))

# --- PCD: integer x/y/z, rgb, padding, an organized 2 x 2 cloud.
PTS = [(-5, 7, -300000), (0, 65535, 12), (127, 1, -1), (-128, 0, 2147483647)]
head = (
    "# .PCD v0.7 - integer coordinates and padding\n"
    "VERSION 0.7\n"
    "FIELDS _ x y rgb z\n"
    "SIZE 1 1 2 4 4\n"
    "TYPE U I U U I\n"
    "COUNT 3 1 1 1 1\n"
    "WIDTH 2\nHEIGHT 2\n"
    "VIEWPOINT 0 0 0 1 0 0 0\n"
    "POINTS 4\n"
    "DATA binary\n"
).encode()
body = b"".join(struct.pack("<3BbHIi", 9, 9, 9, x, y, 0xFF00FF, z) for x, y, z in PTS)
open("python_int_fields.pcd", "wb").write(head + body)

# --- LAS / LAZ via laspy (lazrs backend for LAZ).
X = np.array([0, 100, -250, 123456, 5, -99999], dtype=np.int32)
Y = np.array([7, -7, 70000, 0, 1, 2], dtype=np.int32)
Z = np.array([-1, 0, 1, 2, 3000, -3000], dtype=np.int32)


def las(version, point_format, path):
    h = laspy.LasHeader(version=version, point_format=point_format)
    h.scales = np.array([0.01, 0.01, 0.001])
    h.offsets = np.array([1000.0, 2000.0, 10.0])
    f = laspy.LasData(h)
    f.X, f.Y, f.Z = X, Y, Z
    f.intensity = np.arange(len(X), dtype=np.uint16)
    f.write(path)


las("1.2", 1, "laspy_1_2_format1.las")
las("1.4", 6, "laspy_1_4_format6.las")
las("1.2", 3, "laspy_1_2_format3.laz")
las("1.4", 7, "laspy_1_4_format7.laz")
