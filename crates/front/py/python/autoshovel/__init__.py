"""autoshovel from Python: the Rust toolkit's point clouds, perception, dig,
walk and tracking planners, and its studies.

Point clouds are numpy ``(N, 3)`` float32 arrays (what Open3D's
``np.asarray(pcd.points, dtype=np.float32)`` and laspy's ``xyz`` give once
converted); they are read in place and results come back without a copy.
Parameters are keyword arguments with the library's defaults, results are
typed objects whose fields are those of the command line's
``summary.json``, and the library's errors are :class:`AutoshovelError`
with the message the command line prints. A bad argument is a
``TypeError`` or ``ValueError`` naming it; a missing file is
``FileNotFoundError``.

See ``crates/front/py/README.md`` for a walk through, and ``autoshovel.cluster``
for studies spread over a Ray cluster.
"""

from __future__ import annotations

import os
from typing import Any, Callable, List, Mapping, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import (
    DEFAULT_HEADING_TOLERANCE_DEG,
    DEFAULT_POLISH_EVALUATIONS,
    AutoshovelError,
)
from ._summary import (
    DigPlan,
    Excavation,
    PathPlan,
    Perception,
    StudySummary,
    Summary,
    SurveyPerception,
    Tracking,
)

__all__ = [
    "AutoshovelError",
    "DEFAULT_HEADING_TOLERANCE_DEG",
    "DEFAULT_POLISH_EVALUATIONS",
    "DigPlan",
    "Excavation",
    "PathPlan",
    "Perception",
    "StudySummary",
    "Summary",
    "SurveyPerception",
    "Tracking",
    "generate_pile",
    "level",
    "pass_through",
    "perceive",
    "perceive_survey",
    "plan_dig",
    "plan_excavate",
    "plan_path",
    "radius_outlier_removal",
    "read_cloud",
    "statistical_outlier_removal",
    "study_paths",
    "track",
    "voxel_grid",
    "write_cloud",
]

__version__ = "0.1.0"

PathLike = Union[str, "os.PathLike[str]"]


def _existing(func: str, arg: str, path: PathLike) -> str:
    p = os.fspath(path)
    if not os.path.exists(p):
        raise FileNotFoundError(2, f"{func}(): {arg}: no such file", p)
    return p


def _number(func: str, arg: str, value: Any) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{func}(): {arg} must be a number, got {value!r}") from None
    if not np.isfinite(v):
        raise ValueError(f"{func}(): {arg} = {v}: expected a finite number")
    return v


def _whole(func: str, arg: str, value: Any) -> int:
    """A count or seed: an int (or numpy integer) in 0 .. 2**64 - 1."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{func}(): {arg} must be a whole number, got {value!r}")
    v = int(value)
    if not 0 <= v < 2**64:
        raise ValueError(f"{func}(): {arg} = {v}: expected 0 to 2**64 - 1")
    return v


# ---------------------------------------------------------------- files


def read_cloud(path: PathLike, *, with_info: bool = False):
    """The finite points of a PCD, PLY, LAS, LAZ, XYZ or CSV file as an
    (N, 3) float32 array; with ``with_info`` also the format read and the
    number of non-finite points dropped, as ``(points, format, dropped)``."""
    points, fmt, dropped = _native.read_cloud(_existing("read_cloud", "path", path))
    return (points, fmt, dropped) if with_info else points


def write_cloud(
    path: PathLike,
    points: np.ndarray,
    *,
    encoding: Optional[str] = None,
    overwrite: bool = False,
) -> None:
    """Writes ``points`` to ``path`` in the format its extension names
    (.pcd .ply .las .laz .xyz .csv); ``encoding`` as ``autoshovel
    generate-pile --encoding`` (ascii, binary, binary_compressed,
    binary_big_endian). An existing file is kept unless ``overwrite``; a
    failed write leaves nothing behind."""
    p = os.fspath(path)
    if os.path.exists(p) and not overwrite:
        raise FileExistsError(17, "write_cloud(): path exists (pass overwrite=True to replace it)", p)
    _native.write_cloud(p, points, encoding, overwrite)


# ---------------------------------------------------------------- filters


def voxel_grid(points: np.ndarray, leaf_m: Union[float, Sequence[float]]) -> np.ndarray:
    """PCL's VoxelGrid: the centroid of the points of each occupied voxel of
    edge ``leaf_m`` (one number, or x, y, z) [RS eq. 18]–[RS eq. 19]."""
    if np.ndim(leaf_m) == 0:
        leaf = [_number("voxel_grid", "leaf_m", leaf_m)] * 3
    else:
        leaf = [_number("voxel_grid", f"leaf_m[{i}]", v) for i, v in enumerate(leaf_m)]
        if len(leaf) != 3:
            raise ValueError(f"voxel_grid(): leaf_m must be one number or three, got {len(leaf)}")
    return _native.voxel_grid(points, leaf)


def statistical_outlier_removal(
    points: np.ndarray,
    mean_k: int = 50,
    std_mul: float = 1.0,
    *,
    sides: str = "above",
    return_indices: bool = False,
) -> np.ndarray:
    """PCL's StatisticalOutlierRemoval [RS eq. 14]–[RS eq. 16]: keeps the
    points whose mean distance to their ``mean_k`` nearest neighbours is at
    most the mean plus ``std_mul`` standard deviations (``sides="both"``
    also drops those unusually close, as the paper prints eq. 16). The kept
    points in input order, or their indices (int64)."""
    return _native.statistical_outlier_removal(
        points, _whole("statistical_outlier_removal", "mean_k", mean_k), _number("statistical_outlier_removal", "std_mul", std_mul), sides, return_indices
    )


def radius_outlier_removal(
    points: np.ndarray,
    radius_m: float,
    min_neighbors: int,
    *,
    return_indices: bool = False,
) -> np.ndarray:
    """PCL's RadiusOutlierRemoval [RS eq. 13]: keeps the points with at
    least ``min_neighbors`` others within ``radius_m`` (at the radius
    counts). The kept points in input order, or their indices (int64)."""
    return _native.radius_outlier_removal(
        points,
        _number("radius_outlier_removal", "radius_m", radius_m),
        _whole("radius_outlier_removal", "min_neighbors", min_neighbors),
        return_indices,
    )


def pass_through(
    points: np.ndarray,
    axis: str = "z",
    min_m: float = -np.inf,
    max_m: float = np.inf,
    *,
    keep_inside: bool = True,
    return_indices: bool = False,
) -> np.ndarray:
    """PCL's PassThrough on ``axis``: keeps the points with min_m <= v <=
    max_m (or outside, with ``keep_inside=False``)."""
    for name, v in (("min_m", min_m), ("max_m", max_m)):
        if isinstance(v, float) and np.isnan(v):
            raise ValueError(f"pass_through(): {name} = nan: expected a number")
    return _native.pass_through(points, axis, float(min_m), float(max_m), keep_inside, return_indices)


def level(points: np.ndarray, roll_deg: float, pitch_deg: float) -> np.ndarray:
    """The scan levelled for a sensor with this roll and pitch [deg]
    [RS eq. 11]–[RS eq. 12]."""
    return _native.level(points, roll_deg, pitch_deg)


# ---------------------------------------------------------------- piles and perception


def generate_pile(
    shape: str = "typical",
    points: int = 100_000,
    *,
    scale: float = 1.0,
    roll_deg: float = 3.0,
    pitch_deg: float = -2.0,
    pattern: str = "area",
    sensor_height_m: float = 12.0,
    fov_deg: float = 70.4,
    seed: int = 1,
) -> np.ndarray:
    """A synthetic LiDAR scan of a pile of the rope-shovel paper's Fig. 7
    (typical, convex, concave, convex-concave), as ``autoshovel
    generate-pile`` makes it with the same arguments (``pattern``: area or
    rosette)."""
    f = "generate_pile"
    return _native.generate_pile(
        shape,
        _whole(f, "points", points),
        _number(f, "scale", scale),
        _number(f, "roll_deg", roll_deg),
        _number(f, "pitch_deg", pitch_deg),
        pattern,
        _number(f, "sensor_height_m", sensor_height_m),
        _number(f, "fov_deg", fov_deg),
        _whole(f, "seed", seed),
    )


def perceive(
    cloud: Union[np.ndarray, PathLike],
    *,
    config: Optional[PathLike] = None,
    **settings: Any,
) -> Perception:
    """The rope-shovel paper's §3 pipeline (level, floor, radius and
    statistical outliers, voxel grid, smoothing, surface fit) on an (N, 3)
    float32 array or a file, as ``autoshovel perceive``.

    Settings are those of ``autoshovel perceive --print-config``: a TOML
    file ``config`` and/or keywords, a table as a dict
    (``perceive(pts, statistical={"mean_k": 30}, scale=1.0)``)."""
    cfg = None if config is None else _existing("perceive", "config", config)
    if isinstance(cloud, np.ndarray):
        native = _native.perceive(cloud, None, cfg, settings)
    elif isinstance(cloud, (str, os.PathLike)):
        native = _native.perceive(None, _existing("perceive", "cloud", cloud), cfg, settings)
    else:
        raise TypeError(
            f"perceive(): cloud must be an (N, 3) float32 array or a path, got {type(cloud).__name__}"
        )
    return Perception._from_json(native.summary_json(), _native=native)


Executor = Callable[[str, List[str]], List[str]]


def perceive_survey(
    inputs: Union[PathLike, Sequence[PathLike]],
    *,
    tiles_dir: Optional[PathLike] = None,
    overwrite: bool = False,
    tile_m: Optional[float] = None,
    memory_limit_gib: float = 2.0,
    sample_points: int = 2_000_000,
    model_cell_m: float = 1.0,
    work_dir: Optional[PathLike] = None,
    executor: Optional[Executor] = None,
    config: Optional[PathLike] = None,
    **settings: Any,
) -> SurveyPerception:
    """The §3 pipeline on a LAS/LAZ survey larger than memory, by tiles with
    halos, as ``autoshovel perceive --tiles``: the whole cloud's result in
    bounded memory. ``inputs``: a file, a folder of .las/.laz files, or a
    list of them, taken as one survey in order.

    The cleaned points go to ``tiles_dir`` as ``tile-CCC-RRR.laz`` (written
    beside and moved in when the run succeeds; existing tiles are kept
    unless ``overwrite``). The result's ``height_model`` is the mean
    cleaned height per ``model_cell_m`` cell (rows y, columns x, NaN where
    nothing), its lower corner ``model_origin``.

    Each stage's tiles are tasks; ``executor(stage, tasks) -> reports``
    (JSON text, each task run by ``autoshovel._native.run_tile_task``) may
    run them elsewhere, as :func:`autoshovel.cluster.perceive_survey` does
    on Ray; every worker must then see ``work_dir``, where the run keeps
    its working files (default: the system's temporary folder). Settings:
    as :func:`perceive`."""
    f = "perceive_survey"
    if isinstance(inputs, (str, os.PathLike)):
        items = [inputs]
    elif isinstance(inputs, (list, tuple)) and all(isinstance(p, (str, os.PathLike)) for p in inputs):
        items = list(inputs)
    else:
        raise TypeError(f"{f}(): inputs must be a LAS/LAZ path (file or folder) or a list of them, got {type(inputs).__name__}")
    if not items:
        raise ValueError(f"{f}(): inputs is empty: give a LAS/LAZ file or folder")
    paths = [_existing(f, "inputs", p) for p in items]
    cfg = None if config is None else _existing(f, "config", config)
    limit = _number(f, "memory_limit_gib", memory_limit_gib)
    if limit <= 0:
        raise ValueError(f"{f}(): memory_limit_gib = {limit}: expected a size > 0")
    tiles = None
    if tiles_dir is not None:
        tiles = os.fspath(tiles_dir)
        if os.path.exists(tiles) and not os.path.isdir(tiles):
            raise NotADirectoryError(20, f"{f}(): tiles_dir is a file", tiles)
        if os.path.isdir(tiles) and not overwrite:
            taken = sorted(n for n in os.listdir(tiles) if n.startswith("tile-") and n.endswith(".laz"))
            if taken:
                raise FileExistsError(
                    17, f"{f}(): tiles_dir holds {len(taken)} tile file(s) ({taken[0]}, …): give overwrite=True to replace them", tiles
                )
    if executor is not None and not callable(executor):
        raise TypeError(f"{f}(): executor must be callable(stage, tasks) -> reports, got {type(executor).__name__}")
    text, model, origin, files = _native.perceive_survey(
        paths,
        cfg,
        settings,
        None if tile_m is None else _number(f, "tile_m", tile_m),
        int(limit * 2**30),
        _whole(f, "sample_points", sample_points),
        _number(f, "model_cell_m", model_cell_m),
        None if work_dir is None else _existing(f, "work_dir", work_dir),
        tiles,
        executor,
    )
    return SurveyPerception._from_json(text, height_model=model, model_origin=origin, tile_files=files)


# ---------------------------------------------------------------- planners


def plan_dig(
    pile: Union[str, Perception] = "typical",
    *,
    profile: Optional[PathLike] = None,
    seed: int = 1,
    polish: int = DEFAULT_POLISH_EVALUATIONS,
    search: str = "bends",
    init: str = "good-point-set",
) -> DigPlan:
    """One rope-shovel dig plan (GWO under c1–c18, then a CMA-ES polish),
    as ``autoshovel plan-dig``: on a Fig. 7 pile by name, or on what
    :func:`perceive` returned (the scan cut into a dig profile by the
    library's rule). A pile without a feasible plan is a summary with
    ``success`` False and ``error`` set; a pile the machine cannot dig at
    all is an :class:`AutoshovelError`."""
    prof = None if profile is None else _existing("plan_dig", "profile", profile)
    native_pile = pile._native if isinstance(pile, Perception) else pile
    text, path, surface = _native.plan_dig(
        native_pile, prof, _whole("plan_dig", "seed", seed), _whole("plan_dig", "polish", polish), search, init
    )
    return DigPlan._from_json(text, tooth_path=path, pile_profile=surface)


def plan_path(
    scenario: Union[str, PathLike] = "curve",
    *,
    planner: str = "improved-apf",
    heading_tolerance_deg: float = DEFAULT_HEADING_TOLERANCE_DEG,
) -> PathPlan:
    """The crawler's walk (``autoshovel plan-path``) on a built-in scenario
    (straight, straight-reverse, curve, curve-reverse, v-shape) or a TOML
    file, with the improved (default) or classic ("apf") potential field."""
    text, waypoints = _native.plan_path(
        os.fspath(scenario), planner, _number("plan_path", "heading_tolerance_deg", heading_tolerance_deg)
    )
    return PathPlan._from_json(text, waypoints=waypoints)


def track(
    scenario: Union[str, PathLike] = "fig9a",
    *,
    controller: str = "fuzzy",
    noise: Optional[str] = None,
    seed: int = 1,
    compare: bool = False,
    controllers: Optional[Mapping[str, Any]] = None,
) -> Tracking:
    """Drives the crawler along a scenario in the simulator (``autoshovel
    track``): controller fuzzy, pid, pure-pursuit or stanley; noise off or
    rtk (default: the scenario's); ``controllers`` lays gains over the
    scenario's ``[controller.*]`` tables, e.g. ``{"pid": {"kp": 600}}``."""
    text, trajectory = _native.track(
        os.fspath(scenario), controller, noise, _whole("track", "seed", seed), compare, dict(controllers or {})
    )
    return Tracking._from_json(text, trajectory=trajectory)


def plan_excavate(
    scenario: Union[str, PathLike] = "paper-over",
    *,
    profile: Optional[PathLike] = None,
) -> Excavation:
    """The hydraulic excavator's volume-targeted dig round hidden boulders
    (``autoshovel plan-excavate``): paper-over, paper-under, two-boulders or
    a scenario TOML file."""
    prof = None if profile is None else _existing("plan_excavate", "profile", profile)
    return Excavation._from_json(_native.plan_excavate(os.fspath(scenario), prof))


def study_paths(
    maps: int = 500,
    *,
    seed: int = 1,
    min_obstacles: int = 3,
    max_obstacles: int = 12,
) -> StudySummary:
    """The seeded random haul-road study (``autoshovel study-paths``) on all
    of this machine's cores: the summary and ``table``, the Markdown table
    the command prints. ``autoshovel.cluster`` runs the same study over a
    Ray cluster, with the same numbers."""
    f = "study_paths"
    text, table = _native.study_paths(
        _whole(f, "maps", maps), _whole(f, "seed", seed), _whole(f, "min_obstacles", min_obstacles), _whole(f, "max_obstacles", max_obstacles)
    )
    return StudySummary._from_json(text, table=table)
