"""Tiny PCD reader/writer for the peer scripts (x y z float fields only).

Reads ascii and binary PCD (what PCL's own converter writes); writes ascii PCD
with the shortest decimal that round-trips each float32 exactly, so PCL reads
back the very same floats that our Rust tests read.
"""
import numpy as np


def write_ascii_pcd(path, pts):
    pts = np.asarray(pts, dtype=np.float32)
    n = len(pts)
    with open(path, "w") as f:
        f.write("# .PCD v0.7 - Point Cloud Data file format\n")
        f.write("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n")
        f.write(f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA ascii\n")
        # The shortest decimal that reads back as the very same float32.
        for p in pts:
            f.write(" ".join(np.format_float_positional(v, unique=True, trim="-") for v in p) + "\n")


def write_binary_pcd(path, pts):
    pts = np.ascontiguousarray(np.asarray(pts, dtype="<f4"))
    n = len(pts)
    with open(path, "wb") as f:
        f.write(b"# .PCD v0.7 - Point Cloud Data file format\n")
        f.write(b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n")
        f.write(f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n".encode())
        f.write(pts.tobytes())


def read_pcd(path):
    """x, y, z of an ascii or binary PCD whose fields are all 4-byte floats."""
    with open(path, "rb") as f:
        data = f.read()
    header = {}
    pos = 0
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode().strip()
        pos = end + 1
        if not line or line.startswith("#"):
            continue
        key, _, rest = line.partition(" ")
        header[key] = rest.split()
        if key == "DATA":
            break
    fields = header["FIELDS"]
    n = int(header["POINTS"][0])
    kind = header["DATA"][0]
    if kind == "ascii":
        text = data[pos:].decode().split()
        arr = np.array(text, dtype=np.float32).reshape(n, len(fields)) if n else np.zeros((0, len(fields)), np.float32)
    elif kind == "binary":
        assert all(s == "4" for s in header["SIZE"]) and all(t == "F" for t in header["TYPE"])
        arr = np.frombuffer(data[pos:pos + 4 * n * len(fields)], dtype="<f4").reshape(n, len(fields))
    else:
        raise ValueError(f"{path}: DATA {kind} not handled (convert with pcl_convert_pcd_ascii_binary)")
    idx = [fields.index(c) for c in "xyz"]
    return np.ascontiguousarray(arr[:, idx])
