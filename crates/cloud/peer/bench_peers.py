#!/usr/bin/env python3
"""Time PCL 1.13 and Open3D on the clouds of benches/filters.rs, check that
PCL keeps the very points we keep, and print a table. Run by hand (not by CI):

    apt-get install -y pcl-tools && pip install open3d-cpu   # or open3d
    python3 crates/cloud/peer/bench_peers.py [--runs 3] [--dir /tmp/filter_bench]

It runs `FILTER_BENCH_WRITE=DIR cargo bench -p autoshovel-cloud --bench
filters`, which writes the bench clouds; then, for each filter and size, back
to back so that all three see the same load on the machine: ours (the same
bench binary with FILTER_BENCH_ONLY; median of --runs or half a second of
runs, whichever is longer, after one warm-up run, all threads; it also writes
our output), the PCL tool (--runs runs; the time the tool
prints for the filter alone, "[done, N ms : ...]", so loading and saving are
not counted, but each run is a fresh process) and the Open3D call (timed
around the call alone, the cloud already in memory, repeated as ours); and it
compares PCL's kept points with ours bit for bit.

Parameters (SPEC §4.1 speed aims, adjusted to this cloud's 1.2-3.9 cm
spacing): radius 0.05 m with 5 neighbours; statistical k = 50, multiplier 1;
voxel leaf 0.05 m; pass-through z >= 0.1 m. Open3D's counterparts:
remove_radius_outlier(nb_points=5, radius=0.05) (it keeps more than 5 found,
itself included), remove_statistical_outlier(nb_neighbors=51, std_ratio=1.0)
(itself included; other details differ, see src/filter/statistical_outlier.rs),
voxel_down_sample(0.05) (grid anchored differently),
crop(AxisAlignedBoundingBox(z >= 0.1)).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import pcd  # noqa: E402

ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))

FILTERS = [
    ("pass_through", "pcl_passthrough_filter", ["-field", "z", "-min", "0.1", "-max", "1e30", "-keep", "0"]),
    ("voxel_grid", "pcl_voxel_grid", ["-leaf", "0.05,0.05,0.05"]),
    ("radius", "pcl_outlier_removal", ["-method", "radius", "-radius", "0.05", "-min_pts", "5"]),
    ("statistical", "pcl_outlier_removal", ["-method", "statistical", "-mean_k", "50", "-std_dev_mul", "1.0"]),
]


def pcl_time(tool, inp, out, args):
    """The filter's own time as the tool prints it, and the kept points."""
    res = subprocess.run([tool, inp, out] + args, capture_output=True, text=True)
    log = res.stdout + res.stderr
    if res.returncode != 0:
        raise RuntimeError(f"{tool} failed: {log[-500:]}")
    # Loading, computing, saving: the second "[done, N ms" is the filter.
    ms = [float(m) for m in re.findall(r"\[done, ([0-9.]+) ms", log)]
    conv = out + ".bin.pcd"
    subprocess.run(["pcl_convert_pcd_ascii_binary", out, conv, "1"], capture_output=True, check=True)
    kept = pcd.read_pcd(conv)
    os.remove(conv)
    return ms[1], kept


def open3d_time(o3d, cloud, name):
    t = time.perf_counter()
    if name == "pass_through":
        box = o3d.geometry.AxisAlignedBoundingBox([-1e30, -1e30, 0.1], [1e30, 1e30, 1e30])
        out = cloud.crop(box)
    elif name == "voxel_grid":
        out = cloud.voxel_down_sample(0.05)
    elif name == "radius":
        out, _ = cloud.remove_radius_outlier(nb_points=5, radius=0.05)
    else:
        out, _ = cloud.remove_statistical_outlier(nb_neighbors=51, std_ratio=1.0)
    return (time.perf_counter() - t) * 1e3, len(out.points)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--dir", default="/tmp/filter_bench")
    args = ap.parse_args()

    def ours(only):
        env = dict(os.environ, FILTER_BENCH_WRITE=args.dir, FILTER_BENCH_RUNS=str(args.runs), FILTER_BENCH_ONLY=only)
        out = subprocess.run(["cargo", "bench", "-q", "-p", "autoshovel-cloud", "--bench", "filters"],
                             cwd=ROOT, env=env, capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            m = re.match(r"ours (\S+) (\S+) ([0-9.]+) ms (\d+) points", line)
            if m:
                return float(m.group(3)), int(m.group(4))
        return None

    ours("clouds")
    try:
        import open3d as o3d
        o3d_version = o3d.__version__
    except ImportError:
        o3d = None
        o3d_version = "not installed"
    pcl_version = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "pcl-tools"],
                                 capture_output=True, text=True).stdout.strip()
    print(f"machine: {os.cpu_count()} cores; load average at start {os.getloadavg()[0]:.2f}; "
          f"PCL tools {pcl_version}; Open3D {o3d_version}; runs {args.runs} (median)")
    print("| filter | points | ours [ms] | PCL 1.13 [ms] | Open3D [ms] | PCL / ours | Open3D / ours | kept: ours / PCL / Open3D | same points as PCL |")
    print("|---|---|---|---|---|---|---|---|---|")
    for size in ["100k", "1m"]:
        inp = os.path.join(args.dir, f"pile_{size}.pcd")
        cloud = None
        if o3d is not None:
            cloud = o3d.io.read_point_cloud(inp)
        for name, tool, targs in FILTERS:
            out = os.path.join(args.dir, f"pcl_{name}_{size}.pcd")
            our_ms, our_n = ours(f"{name}:{size}")
            pcl_runs = []
            for _ in range(args.runs):
                ms, kept = pcl_time(tool, inp, out, targs)
                pcl_runs.append(ms)
            pcl_ms = statistics.median(pcl_runs)
            mine = pcd.read_pcd(os.path.join(args.dir, f"ours_{name}_{size}.pcd"))
            if name == "voxel_grid":
                same = len(mine) == len(kept) and bool(np.all(np.abs(mine - kept) <= 1e-5))
                same = "yes (1e-5 m, in order)" if same else "NO"
            else:
                same = "yes (bit for bit, in order)" if np.array_equal(mine.view(np.uint32), kept.view(np.uint32)) else "NO"
            if cloud is not None:
                # One warm-up call, then --runs calls or half a second, as ours.
                open3d_time(o3d, cloud, name)
                o3d_runs, started = [], time.perf_counter()
                while len(o3d_runs) < args.runs or time.perf_counter() - started < 0.5:
                    o3d_runs.append(open3d_time(o3d, cloud, name))
                o3d_ms = statistics.median(r[0] for r in o3d_runs)
                o3d_n = o3d_runs[0][1]
                o3d_cells = (f"{o3d_ms:.1f}", f"{o3d_ms / our_ms:.1f}", str(o3d_n))
            else:
                o3d_cells = ("n/a", "n/a", "n/a")
            print(f"| {name} | {size} | {our_ms:.1f} | {pcl_ms:.1f} | {o3d_cells[0]} | {pcl_ms / our_ms:.1f} | "
                  f"{o3d_cells[1]} | {our_n} / {len(kept)} / {o3d_cells[2]} | {same} |", flush=True)

    print(f"load average at end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
