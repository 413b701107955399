#!/usr/bin/env python3
"""Real sensor scans for `bench_peers.py --input`: PCL's own test clouds.

Five RGB-D scans of PCL's repository (`test/`: an office, five people,
objects on tables, a grabber frame; Kinect-class cameras, 640 x 480, with
the pixels that saw nothing as NaN) are read, their NaN points dropped,
and set side by side 10 m apart along x into one binary PCD of 1.2 M
points: a scan whose pattern (an organized camera grid, density falling
with the square of depth, a few metres deep) no generator of ours made.

    git clone --depth 1 https://github.com/PointCloudLibrary/pcl   # or any checkout
    python3 crates/perception/point-cloud/peer/pcl_scans.py --pcl pcl --out kinect5.pcd
    python3 crates/perception/point-cloud/peer/bench_peers.py --input kinect5.pcd --runs 3 --process

Reading needs Open3D (the scans are LZF-compressed PCD), as
`bench_peers.py` does.
"""

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import pcd  # noqa: E402

SCANS = [
    "test/office1.pcd",
    "test/five_people.pcd",
    "test/milk_cartoon_all_small_clorox.pcd",
    "test/table_scene_mug_stereo_textured.pcd",
    "test/grabber_sequences/pcd/frame_20121214T142256.332395.pcd",
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pcl", required=True, help="a checkout of PointCloudLibrary/pcl")
    ap.add_argument("--out", required=True, help="the PCD to write")
    ap.add_argument("--gap", type=float, default=10.0, help="x offset between scans [m]")
    args = ap.parse_args()
    import open3d as o3d

    parts = []
    for k, rel in enumerate(SCANS):
        path = os.path.join(args.pcl, rel)
        if not os.path.exists(path):
            sys.exit(f"{path}: not found (is --pcl a checkout of PointCloudLibrary/pcl?)")
        pts = np.asarray(o3d.io.read_point_cloud(path, remove_nan_points=False).points, dtype=np.float32)
        pts = pts[np.isfinite(pts).all(axis=1)].copy()
        if len(pts) == 0:
            sys.exit(f"{path}: no finite point")
        pts[:, 0] += np.float32(args.gap * k)
        print(f"{rel}: {len(pts)} points", file=sys.stderr)
        parts.append(pts)
    out = np.concatenate(parts)
    if os.path.exists(args.out):
        sys.exit(f"{args.out}: exists; not overwritten")
    pcd.write_binary_pcd(args.out, out)
    print(f"{args.out}: {len(out)} points", file=sys.stderr)


if __name__ == "__main__":
    main()
