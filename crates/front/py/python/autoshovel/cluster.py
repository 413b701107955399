"""autoshovel's studies spread over a Ray cluster.

Each study is cut into independent units of work by index ranges, never by
chance: map ``i`` of the random-road study is made from the study's seed and
``i`` alone, so a shard ``start..stop`` gives the same rows on any worker
and the gathered result equals the single-machine run for the same seeds
(``autoshovel study-paths``), whatever the cluster's size.

From the shell (``--address`` of a running cluster, ``local`` for a
throwaway one on this machine)::

    python -m autoshovel.cluster --address local study-paths --maps 10000 --seed 1
    python -m autoshovel.cluster --address auto plan-dig SCANS_FOLDER
    python -m autoshovel.cluster --address auto track --controller pid --gain pid.kp=400,800,1200 --seeds 1-8

    python -m autoshovel.cluster --address auto perceive-survey SURVEY.laz --work-dir /shared/tmp --tiles-dir out/tiles

From Python: :func:`study_paths`, :func:`plan_dig_folder`, :func:`track_grid`,
:func:`perceive_survey`.

Ray is this community's engine for many small independent tasks (Dask fits
array pipelines better; these studies are bags of tasks). Every task runs
the library single-threaded (``threads=1``) so that a worker process is one
core and the speed-up from more workers is the cluster's, not rayon's.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import time
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence

import autoshovel
from autoshovel import _native
from autoshovel._summary import StudySummary, SurveyPerception

try:  # Ray is optional: pip install "./crates/front/py[ray]"
    import ray
except ImportError:  # pragma: no cover - said when used
    ray = None


def _need_ray() -> None:
    if ray is None:
        raise ImportError(
            "autoshovel.cluster needs Ray: pip install 'ray[default]' (or ./crates/front/py[ray])"
        )


def shard_ranges(total: int, shards: int) -> List[range]:
    """``0..total`` cut into ``shards`` consecutive ranges of sizes that
    differ by at most one (empty ranges dropped)."""
    if total < 0 or shards < 1:
        raise ValueError(f"shard_ranges(): total = {total}, shards = {shards}: expected total >= 0, shards >= 1")
    base, extra = divmod(total, shards)
    out, start = [], 0
    for i in range(shards):
        stop = start + base + (1 if i < extra else 0)
        if stop > start:
            out.append(range(start, stop))
        start = stop
    return out


def _remote(fn):
    return ray.remote(num_cpus=1)(fn)


def _study_rows(maps: int, seed: int, lo: int, hi: int, start: int, stop: int) -> str:
    return _native.study_paths_rows(maps, seed, lo, hi, start, stop, 1)


def study_paths(
    maps: int = 500,
    *,
    seed: int = 1,
    min_obstacles: int = 3,
    max_obstacles: int = 12,
    shards: Optional[int] = None,
) -> StudySummary:
    """The random-road study as Ray tasks, one per range of map indices
    (default: four per CPU of the cluster), gathered into the summary and
    table of ``autoshovel study-paths`` (same seed, same numbers; only the
    measured plan times differ). Ray must be initialised (``ray.init``)."""
    _need_ray()
    if shards is None:
        shards = max(1, 4 * int(ray.cluster_resources().get("CPU", 1)))
    task = _remote(_study_rows)
    refs = [
        task.remote(maps, seed, min_obstacles, max_obstacles, r.start, r.stop)
        for r in shard_ranges(maps, shards)
    ]
    text, table = _native.study_paths_summary(maps, seed, min_obstacles, max_obstacles, ray.get(refs))
    return StudySummary._from_json(text, table=table)


def _plan_one(path: str, settings: Mapping[str, Any], plan: Mapping[str, Any]) -> Dict[str, Any]:
    try:
        seen = autoshovel.perceive(path, **settings)
        dig = autoshovel.plan_dig(seen, **plan)
        return {"file": path, "perceive": seen.to_dict(), "dig": dig.to_dict(), "error": None}
    except (autoshovel.AutoshovelError, OSError, ValueError) as e:
        return {"file": path, "perceive": None, "dig": None, "error": str(e)}


def plan_dig_folder(
    folder: os.PathLike | str,
    *,
    pattern: str = "*",
    perceive: Optional[Mapping[str, Any]] = None,
    **plan: Any,
) -> List[Dict[str, Any]]:
    """``perceive`` then ``plan_dig`` on every scan in ``folder`` (files
    matching ``pattern`` with a cloud's extension), one Ray task a scan; a
    row per file in name order with both summaries, or the error that
    stopped it."""
    _need_ray()
    exts = {".pcd", ".ply", ".las", ".laz", ".xyz", ".csv"}
    files = sorted(str(p) for p in Path(folder).glob(pattern) if p.suffix.lower() in exts)
    if not files:
        raise FileNotFoundError(2, f"plan_dig_folder(): no scans ({', '.join(sorted(exts))}) match {pattern!r}", str(folder))
    task = _remote(_plan_one)
    return ray.get([task.remote(f, dict(perceive or {}), dict(plan)) for f in files])


def _track_one(scenario: str, controller: str, gains: Mapping[str, Any], seed: int, noise: Optional[str]) -> Dict[str, Any]:
    t = autoshovel.track(scenario, controller=controller, noise=noise, seed=seed, controllers=_nest(gains))
    return {"gains": dict(gains), "seed": seed, "summary": t.to_dict()}


def _nest(flat: Mapping[str, Any]) -> Dict[str, Any]:
    """{"pid.kp": 1} -> {"pid": {"kp": 1}}."""
    out: Dict[str, Any] = {}
    for key, value in flat.items():
        node = out
        *head, last = key.split(".")
        for part in head:
            node = node.setdefault(part, {})
        node[last] = value
    return out


def track_grid(
    scenario: str = "fig9a",
    *,
    controller: str = "fuzzy",
    gains: Mapping[str, Sequence[Any]],
    seeds: Iterable[int] = range(1, 9),
    noise: Optional[str] = "rtk",
) -> List[Dict[str, Any]]:
    """The tracker driven over every combination of ``gains`` (a dotted
    name of the scenario's ``[controller.*]`` tables to its values, e.g.
    ``{"pid.kp": [400, 800]}``) × ``seeds`` (the RTK noise), one Ray task a
    run; a row per run in grid order."""
    _need_ray()
    names = list(gains)
    grid = [dict(zip(names, values)) for values in itertools.product(*(gains[n] for n in names))]
    task = _remote(_track_one)
    refs = [task.remote(scenario, controller, g, s, noise) for g in grid for s in seeds]
    return ray.get(refs)


def _tiles(tasks: List[str], threads: int) -> List[str]:
    return [_native.run_tile_task(t, threads) for t in tasks]


def balanced(weights: Sequence[int], bins: int) -> List[List[int]]:
    """Indices of ``weights`` in at most ``bins`` groups of near-equal sums:
    the heaviest first, each to the lightest group so far (ties to the
    lowest group); empty groups dropped. Deterministic."""
    if bins < 1:
        raise ValueError(f"balanced(): bins = {bins}: expected at least 1")
    groups: List[List[int]] = [[] for _ in range(bins)]
    sums = [0] * bins
    for i in sorted(range(len(weights)), key=lambda i: (-weights[i], i)):
        g = min(range(bins), key=lambda b: (sums[b], b))
        groups[g].append(i)
        sums[g] += weights[i]
    return [g for g in groups if g]


def ray_executor(cpus_per_task: int = 1, tasks_per_cpu: int = 4):
    """An executor for :func:`autoshovel.perceive_survey`: each stage's tile
    tasks packed into ``tasks_per_cpu`` Ray tasks per CPU of the cluster,
    balanced by the points each tile loads (a survey has many near-empty
    edge tiles, and a Ray task costs a millisecond or two), each Ray task
    of ``cpus_per_task`` CPUs (the filters on as many threads); all
    gathered before the next stage."""
    _need_ray()
    if cpus_per_task < 1 or tasks_per_cpu < 1:
        raise ValueError(f"ray_executor(): cpus_per_task = {cpus_per_task}, tasks_per_cpu = {tasks_per_cpu}: expected at least 1")
    remote = ray.remote(num_cpus=cpus_per_task)(_tiles)

    def run(stage: str, tasks: List[str]) -> List[str]:
        cpus = max(1, int(ray.cluster_resources().get("CPU", 1)))
        groups = balanced([_native.tile_task_points(t) for t in tasks], tasks_per_cpu * cpus)
        done = ray.get([remote.remote([tasks[i] for i in g], cpus_per_task) for g in groups])
        return [report for part in done for report in part]

    return run


def perceive_survey(
    inputs: Any,
    *,
    work_dir: Optional[os.PathLike | str] = None,
    cpus_per_task: int = 1,
    **options: Any,
) -> SurveyPerception:
    """:func:`autoshovel.perceive_survey` with each stage's tiles spread
    over the Ray cluster (:func:`ray_executor`): the same result, bit for
    bit, as on one machine. The survey is read, and the cleaned tiles
    written, by this process; the tiles' working files live in
    ``work_dir``, which every worker must see (storage shared by the
    cluster's machines; a local cluster shares this one's). A worker that
    does not see it fails naming the file it could not find."""
    return autoshovel.perceive_survey(inputs, work_dir=work_dir, executor=ray_executor(cpus_per_task), **options)


# ---------------------------------------------------------------- a local cluster


class LocalCluster:
    """A Ray cluster on this machine's loopback: a head with no CPUs of its
    own and ``workers`` worker nodes of ``cpus_per_worker`` CPUs each, as
    separate processes (Ray's ``cluster_utils``); the driver connects to
    it. For tests, benchmarks and trying things; a real cluster is started
    with ``ray start`` and joined with ``--address``."""

    def __init__(self, workers: int = 2, cpus_per_worker: int = 1):
        _need_ray()
        from ray._private import ray_constants
        from ray.cluster_utils import Cluster

        # Every address on loopback: Ray otherwise names a node (and turns a
        # bootstrap address of 127.0.0.1) by the interface that routes
        # outwards. Its single-machine mode (the macOS/Windows default) keeps
        # to 127.0.0.1; this process reads the constant, the nodes it starts
        # read the environment. Undone by shutdown().
        self._saved = (os.environ.get("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"), ray_constants.ENABLE_RAY_CLUSTER)
        os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = "0"
        ray_constants.ENABLE_RAY_CLUSTER = False
        os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
        self.cluster = Cluster(
            initialize_head=True,
            head_node_args={"num_cpus": 0, "include_dashboard": False},
        )
        self.nodes = [self.add_worker(cpus_per_worker) for _ in range(workers)]
        ray.init(address=self.cluster.address, log_to_driver=False)
        self.cluster.wait_for_nodes()

    def add_worker(self, cpus: int = 1):
        """Adds a worker node (a raylet and its worker processes) of ``cpus`` CPUs."""
        return self.cluster.add_node(num_cpus=cpus)

    def __enter__(self) -> "LocalCluster":
        return self

    def __exit__(self, *exc) -> None:
        self.shutdown()

    def shutdown(self) -> None:
        from ray._private import ray_constants

        ray.shutdown()
        self.cluster.shutdown()
        env, constant = self._saved
        if env is None:
            os.environ.pop("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", None)
        else:
            os.environ["RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER"] = env
        ray_constants.ENABLE_RAY_CLUSTER = constant


def _connect(address: str, workers: int) -> Optional[LocalCluster]:
    _need_ray()
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    if address == "local":
        return LocalCluster(workers=workers)
    ray.init(address=address, log_to_driver=False)
    return None


def _parse_seeds(text: str) -> List[int]:
    out: List[int] = []
    for part in text.split(","):
        if "-" in part:
            a, b = part.split("-", 1)
            out.extend(range(int(a), int(b) + 1))
        else:
            out.append(int(part))
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    p = argparse.ArgumentParser(prog="python -m autoshovel.cluster", description=__doc__.split("\n\n")[0])
    p.add_argument("--address", default="local", help="a Ray cluster's address ('auto' for the running one), or 'local' for a head and --workers workers on this machine's loopback")
    p.add_argument("--workers", type=int, default=2, help="worker processes of a 'local' cluster (default 2)")
    p.add_argument("--json", action="store_true", help="print the result as JSON alone")
    sub = p.add_subparsers(dest="study", required=True)
    s = sub.add_parser("study-paths", help="the random-road study (as autoshovel study-paths)")
    s.add_argument("--maps", type=int, default=500)
    s.add_argument("--seed", type=int, default=1)
    s.add_argument("--min-obstacles", type=int, default=3)
    s.add_argument("--max-obstacles", type=int, default=12)
    s.add_argument("--shards", type=int, default=None, help="tasks (default: four per CPU)")
    d = sub.add_parser("plan-dig", help="perceive and plan a dig on every scan of a folder")
    d.add_argument("folder")
    d.add_argument("--pattern", default="*")
    d.add_argument("--seed", type=int, default=1)
    t = sub.add_parser("track", help="a tracker over a grid of gains x seeds")
    t.add_argument("--scenario", default="fig9a")
    t.add_argument("--controller", default="fuzzy")
    t.add_argument("--gain", action="append", default=[], help="NAME=V1,V2,... (e.g. pid.kp=400,800); repeatable")
    t.add_argument("--seeds", default="1-8", help="e.g. 1-8 or 1,5,9")
    v = sub.add_parser("perceive-survey", help="a LAS/LAZ survey by tiles, the tiles of each stage spread over the cluster")
    v.add_argument("inputs", nargs="+", help="LAS/LAZ files or folders, one survey in order")
    v.add_argument("--work-dir", default=None, help="the run's working files: a folder every worker sees (default: the system's temporary folder)")
    v.add_argument("--tiles-dir", default=None, help="where the cleaned tiles go (tile-CCC-RRR.laz)")
    v.add_argument("--tile-size", type=float, default=None, help="tile side [m] (default: from the memory limit and density)")
    v.add_argument("--memory-limit", type=float, default=2.0, help="most working memory of a tile [GiB]")
    v.add_argument("--config", default=None, help="pipeline settings (TOML), as autoshovel perceive --config")
    args = p.parse_args(argv)

    local = _connect(args.address, args.workers)
    try:
        t0 = time.perf_counter()
        if args.study == "study-paths":
            result = study_paths(args.maps, seed=args.seed, min_obstacles=args.min_obstacles, max_obstacles=args.max_obstacles, shards=args.shards)
            wall = time.perf_counter() - t0
            if args.json:
                print(result.to_json())
            else:
                print(result.table)
                print(f"\n{args.maps} maps on {int(ray.cluster_resources().get('CPU', 0))} worker CPUs in {wall:.1f} s", file=sys.stderr)
        elif args.study == "plan-dig":
            rows = plan_dig_folder(args.folder, pattern=args.pattern, seed=args.seed)
            if args.json:
                print(json.dumps(rows, indent=2))
            else:
                for r in rows:
                    dig = r["dig"]
                    if r["error"]:
                        print(f"{r['file']}: {r['error']}")
                    else:
                        if dig["success"]:
                            print(f"{r['file']}: m_dig {dig['m_dig_kg']:.3f} kg, fill {100 * dig['fill_factor']:.0f} %, t_d {dig['td_s']:.2f} s, f {dig['f']:.3f}")
                        else:
                            print(f"{r['file']}: no feasible plan: {dig['error']}")
        elif args.study == "perceive-survey":
            got = perceive_survey(
                args.inputs,
                work_dir=args.work_dir,
                tiles_dir=args.tiles_dir,
                tile_m=args.tile_size,
                memory_limit_gib=args.memory_limit,
                config=args.config,
            )
            wall = time.perf_counter() - t0
            if args.json:
                print(got.to_json())
            else:
                print(
                    f"{got.input}: {got.input_points} points in {got.tiles_used} tiles of {got.tile_m:.1f} m "
                    f"(halo {got.halo_m:.2f} m) -> {got.output_points} cleaned; "
                    + ", ".join(f"{s['stage']} {s['points']}" for s in got.stages)
                )
                print(f"{len(got.tile_files)} tile file(s) written; {wall:.1f} s on {int(ray.cluster_resources().get('CPU', 0))} worker CPUs", file=sys.stderr)
        else:
            gains = {}
            for g in args.gain:
                name, values = g.split("=", 1)
                gains[name] = [float(v) for v in values.split(",")]
            rows = track_grid(args.scenario, controller=args.controller, gains=gains, seeds=_parse_seeds(args.seeds))
            if args.json:
                print(json.dumps(rows, indent=2))
            else:
                for r in rows:
                    m = r["summary"]
                    print(f"{r['gains']} seed {r['seed']}: success {m['success']}, {json.dumps({k: m[k] for k in m if k.endswith('_m')})}")
    finally:
        if local is not None:
            local.shutdown()
        elif ray is not None and ray.is_initialized():
            ray.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
