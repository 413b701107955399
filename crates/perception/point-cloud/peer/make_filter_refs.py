#!/usr/bin/env python3
"""Make the PCL reference data of crates/perception/point-cloud/tests/data/filters/.

Run by hand (not by CI), from anywhere, on a machine with Debian's PCL tools:

    apt-get install -y pcl-tools          # PCL 1.13.0 on Debian 12 (bookworm)
    python3 crates/perception/point-cloud/peer/make_filter_refs.py

It writes the test clouds as ascii PCD (shortest round-trip decimals, so PCL
and our tests read the very same float32 values), runs the PCL command-line
tools on them, and converts each PCL output (written binary_compressed by the
tools) to plain binary PCD with PCL's own pcl_convert_pcd_ascii_binary, which
the tests read with a few lines of code. It also checks, by brute force in
numpy, that the semantics documented in src/filter/ reproduce what PCL kept,
so a disagreement shows here before it shows in `cargo test`. The commands
are listed in tests/data/filters/README.md (written by this script).
"""
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import pcd  # noqa: E402

OUT = os.path.normpath(os.path.join(HERE, "..", "tests", "data", "filters"))
F32 = np.float32


def pile(rng):
    """A 40 degree face, 2.0 x 1.25 m, 2.5 cm grid with jitter, floor in front,
    flat top, 3 mm noise, 1 % outliers, plus points exactly at and next to
    z = 0.1 (the pass-through limit of the tests)."""
    s = 0.025
    xs = np.arange(-0.4, 1.6, s)
    ys = np.arange(0.0, 1.25, s)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    gx = gx + rng.uniform(-0.3 * s, 0.3 * s, gx.shape)
    gy = gy + rng.uniform(-0.3 * s, 0.3 * s, gy.shape)
    z = np.clip(np.tan(np.radians(40.0)) * gx, 0.0, 1.0) + rng.normal(0.0, 0.003, gx.shape)
    pts = np.stack([gx.ravel(), gy.ravel(), z.ravel()], axis=1)
    n_out = len(pts) // 100
    lo, hi = pts.min(axis=0) - 0.2, pts.max(axis=0) + 0.2
    outliers = rng.uniform(lo, hi, (n_out, 3))
    pts = np.concatenate([pts, outliers]).astype(F32)
    edge = []
    for k, zz in enumerate([F32(0.1), np.nextafter(F32(0.1), F32(1)), np.nextafter(F32(0.1), F32(0)),
                            F32(0.5), np.nextafter(F32(0.5), F32(1))]):
        edge.append([F32(0.05 + 0.1 * k), F32(0.3), zz])
    pts = np.concatenate([pts, np.array(edge, dtype=F32)])
    return pts[rng.permutation(len(pts))]


def grid(rng):
    """Boundary cases: a 3-D grid of spacing 0.25 (exact in binary, so
    neighbours sit at exactly r = 0.25 and points on voxel faces), a 2-D grid
    of spacing 0.1 (inexact: float32 squared distances fall on either side of
    r^2 = 0.01), exact duplicates, and a few lone points."""
    g = np.array([[i * 0.25, j * 0.25, k * 0.25] for i in range(8) for j in range(8) for k in range(4)])
    t = np.array([[2.0 + i * 0.1, 2.0 + j * 0.1, 0.3] for i in range(20) for j in range(20)])
    dup = g[rng.choice(len(g), 30, replace=False)]
    lone = np.array([[5.0, 5.0, 5.0], [5.3, 5.0, 5.0], [-3.0, 2.0, 1.0]])
    # Two stars at z = -5: float32 0.1 squared is 0.0100000007 in float32,
    # above the double 0.1 * 0.1 (so PCL counts no neighbour at r = 0.1),
    # but equal to float32 0.1 * 0.1 (a float32 comparison would count four);
    # the arms of the second star are one float32 step shorter.
    a = float(F32(0.1))
    b = float(np.nextafter(F32(0.1), F32(0)))
    stars = np.array([[0, 0, -5], [a, 0, -5], [-a, 0, -5], [0, a, -5], [0, -a, -5],
                      [0, 0, -7], [b, 0, -7], [-b, 0, -7], [0, b, -7], [0, -b, -7]])
    pts = np.concatenate([g, t, dup, dup, lone, stars]).astype(F32)
    return pts[rng.permutation(len(pts))]


def clusters(rng):
    """Gaussian clusters of different spreads and sizes in sparse noise."""
    parts = []
    for c in range(10):
        centre = rng.uniform(-1.5, 1.5, 3)
        sigma = rng.uniform(0.02, 0.12)
        parts.append(rng.normal(centre, sigma, (int(rng.integers(150, 400)), 3)))
    parts.append(rng.uniform(-2.0, 2.0, (300, 3)))
    pts = np.concatenate(parts).astype(F32)
    return pts[rng.permutation(len(pts))]


# name, input cloud, tool, arguments (the exact PCL command line follows from these)
RUNS = [
    ("pile_radius_r0.05_min5", "pile", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.05", "-min_pts", "5"]),
    ("pile_radius_r0.04_min3", "pile", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.04", "-min_pts", "3"]),
    ("grid_radius_r0.25_min6", "grid", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.25", "-min_pts", "6"]),
    ("grid_radius_r0.1_min3", "grid", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.1", "-min_pts", "3"]),
    ("grid_radius_r0.1_min2", "grid", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.1", "-min_pts", "2"]),
    ("clusters_radius_r0.1_min3", "clusters", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.1", "-min_pts", "3"]),
    ("pile_statistical_k50_s1", "pile", "pcl_outlier_removal", ["-method", "statistical", "-mean_k", "50", "-std_dev_mul", "1.0"]),
    ("pile_statistical_k8_s0.5", "pile", "pcl_outlier_removal", ["-method", "statistical", "-mean_k", "8", "-std_dev_mul", "0.5"]),
    ("grid_statistical_k6_s0.2", "grid", "pcl_outlier_removal", ["-method", "statistical", "-mean_k", "6", "-std_dev_mul", "0.2"]),
    ("clusters_statistical_k10_s1", "clusters", "pcl_outlier_removal", ["-method", "statistical", "-mean_k", "10", "-std_dev_mul", "1.0"]),
    ("pile_passthrough_z0.1", "pile", "pcl_passthrough_filter", ["-field", "z", "-min", "0.1", "-max", "1e30", "-keep", "0"]),
    ("pile_passthrough_z0.1_0.5", "pile", "pcl_passthrough_filter", ["-field", "z", "-min", "0.1", "-max", "0.5", "-keep", "0"]),
    ("pile_passthrough_x_outside", "pile", "pcl_passthrough_filter", ["-field", "x", "-min", "0.2", "-max", "0.7", "-inside", "0", "-keep", "0"]),
    ("pile_voxel_0.05", "pile", "pcl_voxel_grid", ["-leaf", "0.05,0.05,0.05"]),
    ("grid_voxel_0.25", "grid", "pcl_voxel_grid", ["-leaf", "0.25,0.25,0.25"]),
    ("clusters_voxel_0.1_0.1_0.2", "clusters", "pcl_voxel_grid", ["-leaf", "0.1,0.1,0.2"]),
]


def run(cmd):
    res = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return res.stdout + res.stderr


def sqdist_f32(a, b):
    """FLANN's L2_Simple<float>: ((0 + dx*dx) + dy*dy) + dz*dz in float32."""
    d = (a[None, :, :] - b[:, None, :]).astype(F32)
    return ((d[..., 0] * d[..., 0]) + (d[..., 1] * d[..., 1])) + (d[..., 2] * d[..., 2])


def expected_radius(pts, r, min_pts):
    keep = []
    r2 = float(r) * float(r)
    for i0 in range(0, len(pts), 512):
        d2 = np.sort(sqdist_f32(pts, pts[i0:i0 + 512]), axis=1)
        keep.extend(d2[:, min_pts].astype(np.float64) <= r2)
    return np.array(keep)


def expected_statistical(pts, k, mul):
    dist = []
    for i0 in range(0, len(pts), 512):
        d2 = np.sort(sqdist_f32(pts, pts[i0:i0 + 512]), axis=1)[:, 1:k + 1]
        s = np.zeros(len(d2))
        for j in range(k):  # sequential double sum, nearest first
            s += np.sqrt(d2[:, j].astype(np.float64))
        dist.extend((s / k).astype(F32))
    dist = np.array(dist, dtype=F32)
    total = 0.0
    sq = 0.0
    for d in dist:  # sequential, as PCL
        total += float(d)
        sq += float(F32(d * d))
    n = float(len(dist))
    mean = total / n
    var = (sq - total * total / n) / (n - 1.0)
    thr = mean + mul * np.sqrt(var)
    return dist.astype(np.float64) <= thr


def kept_indices(inp, out):
    """PCL's outlier and pass-through tools keep input order: match the
    output as a subsequence of the input, bit for bit."""
    idx = []
    j = 0
    for i, p in enumerate(inp):
        if j < len(out) and np.array_equal(p.view(np.uint32), out[j].view(np.uint32)):
            idx.append(i)
            j += 1
    assert j == len(out), "PCL output is not an ordered subsequence of its input"
    return np.array(idx)


def main():
    os.makedirs(OUT, exist_ok=True)
    rng = np.random.default_rng(20240604)
    clouds = {"pile": pile(rng), "grid": grid(rng), "clusters": clusters(rng)}
    for name, pts in clouds.items():
        pcd.write_ascii_pcd(os.path.join(OUT, f"{name}.pcd"), pts)
        print(f"{name}: {len(pts)} points")
    version = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "pcl-tools"],
                             capture_output=True, text=True).stdout.strip()
    lines = []
    tmp = os.path.join(OUT, "tmp_compressed.pcd")
    for name, cloud, tool, args in RUNS:
        inp = os.path.join(OUT, f"{cloud}.pcd")
        out = os.path.join(OUT, f"{name}.pcl.pcd")
        log = run([tool, inp, tmp] + args)
        run(["pcl_convert_pcd_ascii_binary", tmp, out, "1"])
        os.remove(tmp)
        got = pcd.read_pcd(out)
        pts = clouds[cloud]
        m = re.findall(r"\[done, ([0-9.]+) ms : (\d+) points", log)
        lines.append(f"{tool} {cloud}.pcd out.pcd {' '.join(args)}  ->  {name}.pcl.pcd ({len(got)} points)")
        check = ""
        if tool != "pcl_voxel_grid":
            keep = np.zeros(len(pts), bool)
            keep[kept_indices(pts, got)] = True
            a = dict(zip(args[0::2], args[1::2]))
            if a.get("-method") == "radius":
                exp = expected_radius(pts, np.float64(a["-radius"]), int(a["-min_pts"]))
            elif a.get("-method") == "statistical":
                exp = expected_statistical(pts, int(a["-mean_k"]), float(a["-std_dev_mul"]))
            else:
                v = pts[:, "xyz".index(a["-field"])]
                lo, hi = F32(a["-min"]), F32(a["-max"])
                inside = (v >= lo) & (v <= hi)
                exp = inside if a.get("-inside", "1") == "1" else ~inside
            check = "brute force agrees" if np.array_equal(exp, keep) else \
                f"BRUTE FORCE DIFFERS at {np.flatnonzero(exp != keep)[:10]}"
        print(f"{name}: {len(pts)} -> {len(got)}  {check}  (PCL filter {m[1][0] if len(m) > 1 else '?'} ms)")
    with open(os.path.join(OUT, "README.md"), "w") as f:
        f.write(f"""# PCL reference data for the filter tests

Made by `crates/perception/point-cloud/peer/make_filter_refs.py` with Debian's `pcl-tools`
{version} (PCL 1.13.0). Do not edit by hand: rerun the script.

Inputs (ascii PCD, x y z float32, shortest round-trip decimals):

- `pile.pcd`: a 40 degree face with floor and flat top on a 2.5 cm jittered
  grid, 3 mm noise, 1 % outliers, and points at and next to z = 0.1 and 0.5.
- `grid.pcd`: a 3-D grid of spacing 0.25 (neighbours at exactly r = 0.25,
  points on voxel faces), a 2-D grid of spacing 0.1 (float32 squared distances
  on both sides of 0.01), exact duplicates, lone points.
- `clusters.pcd`: Gaussian clusters of different spreads in sparse noise.

Outputs: `NAME.pcl.pcd` is what the PCL tool wrote (binary_compressed),
converted to binary PCD by `pcl_convert_pcd_ascii_binary OUT NAME.pcl.pcd 1`.
The outlier and pass-through tools keep the input order, so the tests compare
our kept points with PCL's bit for bit and in order; the voxel grid output is
compared as a set of centroids within 1e-5 m.

Commands (`in.pcd out.pcd` as named):

```
""")
        for line in lines:
            f.write(line + "\n")
        f.write("```\n")


if __name__ == "__main__":
    main()
