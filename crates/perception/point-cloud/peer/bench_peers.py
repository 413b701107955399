#!/usr/bin/env python3
"""Time PCL 1.13 and Open3D on the clouds of benches/filters.rs, check that
PCL keeps the very points we keep, and print a table. Run by hand (not by CI):

    apt-get install -y pcl-tools && pip install open3d-cpu   # or open3d
    python3 crates/perception/point-cloud/peer/bench_peers.py [--runs 3] [--rounds 1] [--dir /tmp/filter_bench]
        [--sizes 100k,1m,5m,20m | --input SCAN] [--process] [--markdown FILE]
        [--peer-timeout SECONDS]

It runs `FILTER_BENCH_WRITE=DIR cargo bench -p autoshovel-point-cloud --bench
filters`, which writes the bench clouds (or reads --input, a scan made by
anything, e.g. `autoshovel generate-pile --pattern rosette`); then, for each
filter and size, back to back so that all peers see the same load on the
machine: ours (the same
bench binary with FILTER_BENCH_ONLY; median of --runs or half a second of
runs, whichever is longer, after one warm-up run, all threads; it also writes
our output), the PCL tool (--runs runs, --big-runs at 5 M points and more;
the time the tool prints for the filter alone, "[done, N ms : ...]", so
loading and saving are not counted, but each run is a fresh process) and
Open3D's legacy (o3d.geometry) and tensor (o3d.t.geometry, float32, CPU)
calls (timed around the call alone, the cloud already in memory, repeated as
ours); and it compares PCL's kept points with ours bit for bit. With
--rounds N all of that is done N times over, ours and the peers in turn,
and a row gives the medians of the rounds and the median of the rounds'
ratios with their range: on a shared VM whose speed drifted by half
within twenty minutes, one round's ratio moved between 10.6 and 16.1
(statistical removal on kinect5, three runs within three minutes,
2026-12-06). With
--process it also times `autoshovel filter` and the PCL tool as whole
processes (read, filter, write).

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
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import pcd  # noqa: E402

ROOT = os.path.normpath(os.path.join(HERE, "..", "..", ".."))

# The voxel edge of every peer's voxel grid [m].
VOXEL_LEAF = 0.05


def exact_voxel_means(pts, leaf):
    """The exact (f64) mean of each of PCL's voxels, in PCL's order.

    A point's voxel is floor(p * (1 / leaf)) computed in f32, as PCL 1.13
    computes it; the voxels are ordered by PCL's linear index (x fastest).
    The independent reference for both PCL's centroids (summed in f32) and
    ours (summed in f64).
    """
    pts = pts[np.isfinite(pts).all(axis=1)]
    inv = np.float32(1.0) / np.float32(leaf)
    ijk = np.floor(pts * inv).astype(np.int64)
    lo = ijk.min(axis=0)
    ext = ijk.max(axis=0) - lo + 1
    rel = ijk - lo
    lin = rel[:, 0] + rel[:, 1] * ext[0] + rel[:, 2] * ext[0] * ext[1]
    order = np.argsort(lin, kind="stable")
    _, start = np.unique(lin[order], return_index=True)
    sums = np.add.reduceat(pts[order].astype(np.float64), start, axis=0)
    counts = np.diff(np.append(start, len(order)))
    return sums / counts[:, None]


FILTERS = [
    ("pass_through", "pcl_passthrough_filter", ["-field", "z", "-min", "0.1", "-max", "1e30", "-keep", "0"]),
    ("voxel_grid", "pcl_voxel_grid", ["-leaf", ",".join([str(VOXEL_LEAF)] * 3)]),
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


def open3d_time(o3d, cloud, name, tensor):
    """Open3D's legacy API (o3d.geometry), or its tensor API (o3d.t.geometry,
    float32 points on the CPU) with `tensor`."""
    t = time.perf_counter()
    if name == "pass_through":
        lo, hi = [-1e30, -1e30, 0.1], [1e30, 1e30, 1e30]
        if tensor:
            f32 = o3d.core.float32
            box = o3d.t.geometry.AxisAlignedBoundingBox(o3d.core.Tensor(lo, f32), o3d.core.Tensor(hi, f32))
        else:
            box = o3d.geometry.AxisAlignedBoundingBox(lo, hi)
        out = cloud.crop(box)
    elif name == "voxel_grid":
        out = cloud.voxel_down_sample(VOXEL_LEAF)
    elif name == "radius" and tensor:
        out, _ = cloud.remove_radius_outliers(nb_points=5, search_radius=0.05)
    elif name == "radius":
        out, _ = cloud.remove_radius_outlier(nb_points=5, radius=0.05)
    elif tensor:
        out, _ = cloud.remove_statistical_outliers(nb_neighbors=51, std_ratio=1.0)
    else:
        out, _ = cloud.remove_statistical_outlier(nb_neighbors=51, std_ratio=1.0)
    ms = (time.perf_counter() - t) * 1e3
    return ms, len(out.point.positions) if tensor else len(out.points)


def repeat(fn, runs, warm=True):
    """One warm-up call (unless not `warm`), then `runs` calls or half a
    second, as ours; the median and the first result; (None, reason) when
    the call runs out of the memory limit (Open3D's radius search keeps
    every neighbour)."""
    results, started = [], time.perf_counter()
    try:
        if warm:
            fn()
        else:
            results.append(fn())
    except (MemoryError, RuntimeError) as e:
        text = re.sub(r"\x1b\[[0-9;]*m", "", str(e))
        why = "out of memory" if isinstance(e, MemoryError) or "Memory" in text else text.splitlines()[0][:60]
        return None, f"failed: {why or type(e).__name__}"
    if warm:
        started = time.perf_counter()
    while len(results) < runs or time.perf_counter() - started < 0.5:
        results.append(fn())
    return statistics.median(r[0] for r in results), results[0][1]


def open3d_in_child(inp, name, tensor, runs, warm, timeout_s):
    """`repeat` of one Open3D call in a child process that reads `inp`
    itself (not timed), stopped after `timeout_s` seconds: (median ms, kept)
    or (None, reason). Open3D's legacy radius filter at 20 M points runs for
    tens of minutes; the row still gets PCL's time and the lower bound."""
    cmd = [sys.executable, os.path.abspath(__file__), "--open3d-one", inp, name, str(int(tensor)),
           str(runs), str(int(warm))]
    try:
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return None, f"over {timeout_s:.0f} s (stopped)"
    lines = res.stdout.strip().splitlines()
    if res.returncode != 0 or not lines:
        return None, f"failed: {(res.stderr.strip().splitlines() or ['exit %d' % res.returncode])[-1][:60]}"
    ms, kept = json.loads(lines[-1])
    return ms, kept


def open3d_one(argv):
    """The child of `open3d_in_child`: prints `repeat`'s pair as JSON."""
    import open3d as o3d
    inp, name, tensor, runs, warm = argv[0], argv[1], argv[2] == "1", int(argv[3]), argv[4] == "1"
    cloud = o3d.io.read_point_cloud(inp)
    if tensor:
        cloud = o3d.t.geometry.PointCloud.from_legacy(cloud, o3d.core.float32)
    ms, kept = repeat(lambda: open3d_time(o3d, cloud, name, tensor), runs, warm)
    print(json.dumps([ms, kept]))


# `autoshovel filter` flags of each filter, for the whole-process timing.
OUR_FLAGS = {
    "pass_through": ["--pass", "z:0.1:1e30"],
    "voxel_grid": ["--voxel", str(VOXEL_LEAF)],
    "radius": ["--radius", "0.05,5"],
    "statistical": ["--statistical", "50,1.0"],
}


def process_ms(cmd):
    t = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {(res.stdout + res.stderr)[-500:]}")
    return (time.perf_counter() - t) * 1e3


def main():
    if sys.argv[1:2] == ["--open3d-one"]:
        open3d_one(sys.argv[2:])
        return
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--rounds", type=int, default=1,
                    help="times each row's measurements are repeated, ours and the peers' alternating; "
                         "medians of the rounds, and the ratio as the median of the rounds' ratios with its range")
    ap.add_argument("--big-runs", type=int, default=1,
                    help="PCL and Open3D runs at 5 M points and more (Open3D without a warm-up); ours keeps --runs")
    ap.add_argument("--dir", default="/tmp/filter_bench")
    ap.add_argument("--sizes", default="100k,1m,5m,20m", help="bench pile sizes, e.g. 100k,1m,5m,20m")
    ap.add_argument("--input", help="a scan of your own (any format autoshovel reads) instead of the bench pile")
    ap.add_argument("--filters", default=",".join(f[0] for f in FILTERS))
    ap.add_argument("--process", action="store_true",
                    help="also time `autoshovel filter` and the PCL tool as whole processes (read, filter, write)")
    ap.add_argument("--markdown", help="also write the table to this file")
    ap.add_argument("--peer-timeout", type=float, default=None,
                    help="at 5 M points and more, run each Open3D call in a child process and stop it after this "
                         "many seconds (the cell then gives the bound); PCL and ours always run to the end")
    ap.add_argument("--memory-limit-gb", type=float, default=None,
                    help="address-space limit of this script and its children (default: 3/4 of the machine's memory), "
                         "so that a peer that runs out fails alone instead of the machine killing the run")
    args = ap.parse_args()
    wanted = args.filters.split(",")
    limit = args.memory_limit_gb
    if limit is None:
        limit = 0.75 * os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    resource.setrlimit(resource.RLIMIT_AS, (int(limit * 2**30), resource.RLIM_INFINITY))
    lines = []

    def say(line):
        print(line, flush=True)
        lines.append(line)

    def ours(only, size):
        env = dict(os.environ, FILTER_BENCH_WRITE=args.dir, FILTER_BENCH_RUNS=str(args.runs), FILTER_BENCH_ONLY=only)
        if args.input:
            env["FILTER_BENCH_INPUT"] = os.path.abspath(args.input)
        else:
            env["FILTER_BENCH_SIZES"] = size
        out = subprocess.run(["cargo", "bench", "-q", "-p", "autoshovel-point-cloud", "--bench", "filters"],
                             cwd=ROOT, env=env, capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            m = re.match(r"ours (\S+) (\S+) ([0-9.]+) ms (\d+) points", line)
            if m:
                return float(m.group(3)), int(m.group(4))
        return None

    if args.input:
        sizes = [os.path.splitext(os.path.basename(args.input))[0]]
    else:
        sizes = [s.strip().lower() for s in args.sizes.split(",")]
    for size in sizes:
        ours("clouds", size)
    # The clouds just written (0.24 GB at 20 M points) are flushed before
    # anything is timed, so that no writeback shares the cores with a
    # timed run. (It was suspected, not shown, in two slow 20 M runs of our
    # voxel grid: BENCHMARKS.md, 2026-12-05 21:36-00:36.)
    os.sync()
    binary = None
    if args.process:
        subprocess.run(["cargo", "build", "-q", "--release", "-p", "autoshovel"], cwd=ROOT, check=True)
        binary = os.path.join(ROOT, "target", "release", "autoshovel")
    try:
        import open3d as o3d
        o3d_version = o3d.__version__
    except ImportError:
        o3d = None
        o3d_version = "not installed"
    pcl_version = subprocess.run(["dpkg-query", "-W", "-f", "${Version}", "pcl-tools"],
                                 capture_output=True, text=True).stdout.strip()
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    say(f"machine: {cpu}, {os.cpu_count()} cores; {time.strftime('%Y-%m-%d %H:%M')}; load average at start "
        f"{os.getloadavg()[0]:.2f}; PCL tools {pcl_version}; Open3D {o3d_version}; runs {args.runs} "
        f"(PCL {args.big_runs} at 5 M points and more); times in ms, medians")
    say("")
    head = ("| filter | cloud | points | ours | PCL | Open3D | Open3D tensor | best peer ÷ ours "
            "| kept: ours / PCL / Open3D / Open3D t | same points as PCL |")
    rule = "|---|---|---|---|---|---|---|---|---|---|"
    if args.process:
        head += " ours, whole process | PCL tool, whole process |"
        rule += "---|---|"
    say(head)
    say(rule)
    for size in sizes:
        inp = os.path.join(args.dir, f"pile_{size}.pcd")
        cloud = cloud_t = None
        if o3d is not None:
            cloud = o3d.io.read_point_cloud(inp)
            cloud_t = o3d.t.geometry.PointCloud.from_legacy(cloud, o3d.core.float32)
            n_points = len(cloud.points)
        else:
            n_points = len(pcd.read_pcd(inp))
        pcl_runs_n = args.runs if n_points < 5_000_000 else args.big_runs
        for name, tool, targs in FILTERS:
            if name not in wanted:
                continue
            out = os.path.join(args.dir, f"pcl_{name}_{size}.pcd")
            # Each round times ours, then PCL, then Open3D's two APIs, back
            # to back; with --rounds > 1 the rounds alternate the peers
            # over the machine's drift, and the ratio is the median of the
            # rounds' ratios.
            rounds = []
            for _ in range(args.rounds):
                our_ms, our_n = ours(f"{name}:{size}", size)
                pcl_runs = []
                for _ in range(pcl_runs_n):
                    ms, kept = pcl_time(tool, inp, out, targs)
                    pcl_runs.append(ms)
                o3d_ms = o3t_ms = None
                o3d_n = o3t_n = "n/a"
                if cloud is not None:
                    # At 5 M points and more, --big-runs runs and no warm-up, as PCL.
                    big = n_points >= 5_000_000
                    if big and args.peer_timeout:
                        o3d_ms, o3d_n = open3d_in_child(inp, name, False, pcl_runs_n, False, args.peer_timeout)
                        o3t_ms, o3t_n = open3d_in_child(inp, name, True, pcl_runs_n, False, args.peer_timeout)
                    else:
                        o3d_ms, o3d_n = repeat(lambda: open3d_time(o3d, cloud, name, False), pcl_runs_n, not big)
                        o3t_ms, o3t_n = repeat(lambda: open3d_time(o3d, cloud_t, name, True), pcl_runs_n, not big)
                rounds.append((our_ms, statistics.median(pcl_runs), o3d_ms, o3t_ms))

            def middle(j):
                got = [r[j] for r in rounds if r[j] is not None]
                return statistics.median(got) if got else None

            our_ms, pcl_ms, o3d_ms, o3t_ms = (middle(j) for j in range(4))
            ratios = [min(m for m in r[1:] if m is not None) / r[0] for r in rounds]
            ratio = f"{statistics.median(ratios):.1f}"
            if len(ratios) > 1:
                ratio += f" ({min(ratios):.1f}–{max(ratios):.1f} over {len(ratios)} rounds)"
            mine = pcd.read_pcd(os.path.join(args.dir, f"ours_{name}_{size}.pcd"))
            if name == "voxel_grid":
                # PCL sums a voxel's points in f32, we in f64: both are held
                # to the exact mean (f64) of PCL's voxels, in PCL's order.
                exact = exact_voxel_means(pcd.read_pcd(inp), VOXEL_LEAF)
                if len(mine) == len(kept) == len(exact) and len(mine) > 0:
                    ours_gap = float(np.abs(mine - exact).max())
                    pcl_gap = float(np.abs(kept - exact).max())
                    tol = max(1e-5, 1e-6 * float(np.abs(exact).max()), pcl_gap)
                    same = (f"yes (same voxels in order; centroids within {ours_gap:.1e} m of the exact "
                            f"means, PCL's within {pcl_gap:.1e} m)") if ours_gap <= tol else \
                        f"NO (centroids {ours_gap:.1e} m off the exact means, PCL's {pcl_gap:.1e} m)"
                else:
                    same = f"NO (voxel counts differ: exact {len(exact)})"
            else:
                same = "yes (bit for bit, in order)" if np.array_equal(mine.view(np.uint32), kept.view(np.uint32)) else "NO"
            if cloud is not None:
                o3d_cells = tuple(f"{m:.1f}" if m is not None else n for m, n in ((o3d_ms, o3d_n), (o3t_ms, o3t_n))) \
                    + (str(o3d_n) if o3d_ms is not None else "–", str(o3t_n) if o3t_ms is not None else "–")
            else:
                o3d_cells = ("n/a", "n/a", "n/a", "n/a")
            row = (f"| {name} | {'bench pile' if not args.input else args.input} | {size} | {our_ms:.1f} | {pcl_ms:.1f} "
                   f"| {o3d_cells[0]} | {o3d_cells[1]} | {ratio} "
                   f"| {our_n} / {len(kept)} / {o3d_cells[2]} / {o3d_cells[3]} | {same} |")
            if args.process:
                mine_out = os.path.join(args.dir, f"process_{name}_{size}.pcd")
                ours_p = statistics.median(
                    process_ms([binary, "filter", "--input", inp, "--output", mine_out, "--force"] + OUR_FLAGS[name])
                    for _ in range(pcl_runs_n))
                pcl_p = statistics.median(process_ms([tool, inp, out] + targs) for _ in range(pcl_runs_n))
                row += f" {ours_p:.0f} | {pcl_p:.0f} |"
            say(row)

    say("")
    say(f"load average at end {os.getloadavg()[0]:.2f}")
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
