"""What a call from Python costs beside the same call from Rust, and what a
study gains from one to two Ray worker processes (BENCHMARKS.md, "Python").

    python crates/front/py/bench/bench_calls.py [--points 1000000] [--repeats 7] [--maps 2000] [--survey-points 2000000]

Calls: each filter and ``perceive`` on one generated pile (the Livox-like
rosette pattern, 1.5 % outliers), timed from Python (``autoshovel.voxel_grid``
...) and from Rust inside the same process on the very same array
(``_native._time_in_rust``), interleaved, median of ``--repeats``.

Ray: the random-road study of ``--maps`` maps on a local cluster of one
worker process, then of two (each task one thread), against the same
study on one thread without Ray; and a survey by tiles, each stage's
tiles as Ray tasks on one worker process, then two, against the same
survey in this process on every core.
"""

import argparse
import os
import statistics
import sys
import time

import numpy as np

import autoshovel
from autoshovel import _native


def median_ms(times):
    return 1e3 * statistics.median(times)


def calls(points: int, repeats: int) -> None:
    pts = autoshovel.generate_pile("typical", points, pattern="rosette", seed=1)
    lo, hi = float(np.quantile(pts[:, 2], 0.1)), float(np.quantile(pts[:, 2], 0.9))
    py_calls = {
        "voxel": lambda: autoshovel.voxel_grid(pts, 0.05),
        "statistical": lambda: autoshovel.statistical_outlier_removal(pts, 50, 1.0),
        "radius": lambda: autoshovel.radius_outlier_removal(pts, 0.05, 3),
        "pass": lambda: autoshovel.pass_through(pts, "z", lo, hi),
        "perceive": lambda: autoshovel.perceive(pts),
    }
    print(f"| call ({points:,} points, rosette) | from Python | from Rust | Python / Rust |")
    print("|---|---|---|---|")
    for kind, call in py_calls.items():
        call()  # warm
        py, rs = [], []
        for _ in range(repeats):
            t0 = time.perf_counter()
            call()
            py.append(time.perf_counter() - t0)
            rs.extend(_native._time_in_rust(kind, pts, 1, lo, hi))
        p, r = median_ms(py), median_ms(rs)
        print(f"| {kind} | {p:.1f} ms | {r:.1f} ms | {p / r:.3f} |")


def ray_speedup(maps: int) -> None:
    from autoshovel import cluster

    t0 = time.perf_counter()
    _native.study_paths_rows(maps, 1, 3, 12, 0, maps, 1)
    alone = time.perf_counter() - t0
    rows = [f"| one thread, no Ray | {alone:.1f} s | 1.00 |"]
    walls = {}
    for workers in (1, 2):
        with cluster.LocalCluster(workers=workers):
            cluster.study_paths(8 * workers, shards=workers)  # start the worker processes
            t0 = time.perf_counter()
            s = cluster.study_paths(maps, shards=16)
            walls[workers] = time.perf_counter() - t0
        rows.append(f"| Ray, {workers} worker process{'es' if workers > 1 else ''} | {walls[workers]:.1f} s | {alone / walls[workers]:.2f} |")
    print(f"\n| random-road study, {maps:,} maps (16 tasks) | wall | speed-up |")
    print("|---|---|---|")
    print("\n".join(rows))
    print(f"\nfrom 1 to 2 worker processes: {walls[1] / walls[2]:.2f}x")


def survey_speedup(points: int, repeats: int) -> None:
    """A survey of ``points`` (the rosette pile in one LAZ file, tiles of
    2 m) by tiles in this process (every core), then with each stage's
    tiles as Ray tasks on one worker process, then on two; medians of
    ``repeats`` runs after a warm-up."""
    import tempfile

    from autoshovel import cluster

    def timed(run):
        run()  # warm: the worker processes, the page cache
        walls = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            got = run()
            walls.append(time.perf_counter() - t0)
        return statistics.median(walls), got

    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "survey.laz")
        autoshovel.write_cloud(path, autoshovel.generate_pile("typical", points, pattern="rosette", seed=1))
        walls, tiled = {}, {}

        def tile_stages(got):
            return sum(st["ms"] for st in got.stages if st["stage"] in ("radius", "statistical", "voxel", "smooth")) / 1e3

        walls[0], here = timed(lambda: autoshovel.perceive_survey(path, tile_m=2.0, work_dir=d))
        tiled[0] = tile_stages(here)
        for workers in (1, 2):
            with cluster.LocalCluster(workers=workers):
                walls[workers], got = timed(lambda: cluster.perceive_survey(path, tile_m=2.0, work_dir=d))
            tiled[workers] = tile_stages(got)
            assert got.to_dict()["stage_points"] == here.to_dict()["stage_points"]
    print(f"\n| survey by tiles, {points:,} points, {here.tiles_used} tiles of 2 m (median of {repeats}) | wall | the tile stages (last run) | speed-up |")
    print("|---|---|---|---|")
    print(f"| this process, every core (rayon within a tile) | {walls[0]:.1f} s | {tiled[0]:.1f} s | 1.00 |")
    for w in (1, 2):
        print(f"| Ray, {w} worker process{'es' if w > 1 else ''} (tiles packed four tasks a CPU, one thread each) | {walls[w]:.1f} s | {tiled[w]:.1f} s | {walls[0] / walls[w]:.2f} |")
    print(f"\nfrom 1 to 2 worker processes: {walls[1] / walls[2]:.2f}x (the tile stages: {tiled[1] / tiled[2]:.2f}x)")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--maps", type=int, default=2000)
    ap.add_argument("--survey-points", type=int, default=2_000_000)
    ap.add_argument("--skip-calls", action="store_true")
    ap.add_argument("--skip-ray", action="store_true")
    a = ap.parse_args()
    print(f"autoshovel {autoshovel.__version__}, Python {sys.version.split()[0]}, numpy {np.__version__}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d')}\n")
    if not a.skip_calls:
        calls(a.points, a.repeats)
    if not a.skip_ray:
        ray_speedup(a.maps)
        survey_speedup(a.survey_points, a.repeats)
    return 0


if __name__ == "__main__":
    sys.exit(main())
