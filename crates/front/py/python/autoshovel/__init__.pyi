# Type stubs of the package `autoshovel` (editors complete the API from
# these). The fields of each result class are those of the command line's
# summary.json for the job; tests/test_stubs.py holds them to the summaries
# the library makes.
from os import PathLike
from typing import Any, Callable, Iterator, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from . import cluster as cluster

__version__: str
DEFAULT_POLISH_EVALUATIONS: int
DEFAULT_HEADING_TOLERANCE_DEG: float

Points = npt.NDArray[np.float32]
"""An (N, 3) float32 C-contiguous array of points [m]."""

class AutoshovelError(Exception):
    """An error of the autoshovel library, with the message the command line prints."""

class Summary(Mapping[str, Any]):
    """A job's summary: the fields of summary.json as attributes and keys."""
    def __getattr__(self, name: str) -> Any: ...
    def __getitem__(self, key: str) -> Any: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def to_dict(self) -> dict[str, Any]: ...
    def to_json(self, indent: Optional[int] = 2) -> str: ...

class Perception(Summary):
    """What perceive() made: `autoshovel perceive --json`'s fields, the points and the surface."""
    change: Optional[Summary]
    fit: Summary
    floor_height_m: float
    floor_points: int
    floor_rms_m: float
    floor_share: float
    format: str
    ground_mode: str
    ground_note: Optional[str]
    height_model: Summary
    input: str
    input_points: int
    job: str
    level_mode: str
    non_finite_dropped: int
    origin: list[float]
    output_points: int
    pipeline: Summary
    pitch_deg: float
    points_below_floor: int
    r2: float
    roll_deg: float
    scale: float
    spacing_m: float
    stage_points: Summary
    stages: list[Any]
    success: bool
    timings_ms: Summary
    total_ms: float
    volume_base_m: Optional[float]
    volume_m3: float
    warnings: list[str]
    @property
    def points(self) -> npt.NDArray[np.float32]: ...
    def surface_height(self, x: npt.ArrayLike, y: npt.ArrayLike) -> npt.NDArray[np.float64]: ...

class SurveyPerception(Summary):
    """What perceive_survey() made: `autoshovel perceive --tiles --json`'s fields, the height model and the tiles written."""
    fit: Optional[Summary]
    fit_note: Optional[str]
    files: list[str]
    floor_height_m: float
    floor_points: int
    floor_rms_m: float
    floor_share: float
    format: str
    grid: list[int]
    halo_m: float
    input: str
    input_points: int
    job: str
    largest_tile_points: int
    memory_limit_bytes: int
    mode: str
    model_cell_m: float
    model_size: list[int]
    non_finite_dropped: int
    origin_m: list[float]
    output_points: int
    peak_memory_bytes: Optional[int]
    pipeline: Summary
    pitch_deg: float
    points_below_floor: int
    points_per_s: float
    r2: Optional[float]
    roll_deg: float
    sample_points: int
    scale: float
    spacing_m: float
    stage_points: Summary
    stages: list[Any]
    statistical_researched: int
    success: bool
    tile_m: float
    tiles_used: int
    timings_ms: Summary
    total_ms: float
    warnings: list[str]
    height_model: npt.NDArray[np.float64]
    model_origin: tuple[float, float]
    tile_files: list[str]

class DigPlan(Summary):
    """A dig plan: `autoshovel plan-dig --json`'s fields, the tooth path and the pile's profile."""
    ax6: float
    ay6: float
    bend_x_m: float
    bend_y_m: float
    constraint_handling: str
    constraints: Summary
    crowd_energy_j: float
    density_kg_m3: float
    epsilon: float
    evaluations: int
    f: float
    f1_j_per_kg: float
    f2_s_per_kg: float
    feasible: bool
    fill_factor: float
    first_feasible_iteration: int
    geometry: Summary
    gx_m: float
    gy_m: float
    hoist_energy_j: float
    init: str
    iterations: int
    job: str
    k1: float
    k2: float
    k_f_pa: float
    m_dig_kg: float
    plan_time_ms: float
    polish_evaluations: int
    population: int
    profile: str
    psi: float
    samples: int
    search_space: str
    seed: int
    success: bool
    surface: str
    surface_source: str
    td_s: float
    volume_m3: float
    tooth_path: npt.NDArray[np.float64]
    pile_profile: npt.NDArray[np.float64]

class PathPlan(Summary):
    """A walk plan: `autoshovel plan-path --json`'s fields and the waypoints."""
    cusp_heading_error_deg: float
    error: Optional[str]
    error_at_m: Optional[float]
    escape_strategy: Optional[str]
    escapes: int
    final_heading_error_deg: float
    footprint_radius_m: float
    heading_tolerance_deg: float
    iterations: int
    job: str
    legs: list[Any]
    length_m: float
    local_minimum: bool
    max_curvature_per_m: float
    mean_abs_curvature_per_m: float
    min_clearance_at_m: list[Any]
    min_clearance_m: float
    params: Summary
    plan_time_ms: float
    planner: str
    reference: Summary
    scenario: str
    start_heading_error_deg: float
    success: bool
    waypoints: npt.NDArray[np.float64]

class Tracking(Summary):
    """A tracking run: `autoshovel track --json`'s fields and the main run's trajectory."""
    completed: bool
    controller: str
    converged_below_m: float
    convergence_distance_m: float
    duration_s: float
    events: list[Any]
    final_heading_error_deg: float
    final_position_error_m: float
    gains: Summary
    job: str
    max_centroid_dev_m: float
    max_centroid_dev_overall_m: float
    mean_centroid_dev_m: float
    mean_centroid_dev_overall_m: float
    noise: str
    params: Summary
    reached_distance_m: float
    realtime_factor: float
    rms_centroid_dev_m: float
    safety_events: int
    scenario: str
    seed: int
    settled_1cm_distance_m: float
    sim_time_ms: float
    success: bool
    travelled_m: float
    trajectory: npt.NDArray[np.float64]

class Excavation(Summary):
    """A hydraulic-excavator dig: `autoshovel plan-excavate --json`'s fields."""
    achieved_volume_m3: float
    avoid_direction: str
    avoid_directions: list[Any]
    believed_volume_m3: float
    contact_count: int
    contacts: list[Any]
    depth_m: float
    description: str
    detours: list[Any]
    duration_s: float
    estimates: list[Any]
    final_tip_m: list[Any]
    job: str
    level1: Summary
    level1_end_m: list[Any]
    level1_mid_m: list[Any]
    level1_start_m: list[Any]
    max_digging_force_n: float
    max_joint_step_ratio: float
    min_envelope_distance_m: float
    obstacle_volume_m3: float
    obstacles: list[Any]
    peak_digging_force_n: float
    peak_soil_force_n: float
    peak_torques_nm: list[Any]
    plan_time_ms: float
    prior_radius_m: float
    profile: str
    refine_volume: bool
    samples: int
    scenario: str
    scenario_source: str
    segments: list[Any]
    soil_volume_m3: float
    step_m: float
    target_volume_m3: float
    volume_error: float
    volume_error_pct: float

class StudySummary(Summary):
    """The random-road study: `autoshovel study-paths --json`'s fields and the table."""
    command: str
    heading_tolerance_deg: float
    job: str
    maps: int
    planners: list[Any]
    reference: Summary
    seed: int
    success: bool
    table: str

def read_cloud(path: Union[str, PathLike[str]], *, with_info: bool = False) -> Any: ...
def write_cloud(path: Union[str, PathLike[str]], points: Points, *, encoding: Optional[str] = None, overwrite: bool = False) -> None: ...
def voxel_grid(points: Points, leaf_m: Union[float, Sequence[float]]) -> Points: ...
def statistical_outlier_removal(points: Points, mean_k: int = 50, std_mul: float = 1.0, *, sides: str = "above", return_indices: bool = False) -> npt.NDArray[Any]: ...
def radius_outlier_removal(points: Points, radius_m: float, min_neighbors: int, *, return_indices: bool = False) -> npt.NDArray[Any]: ...
def pass_through(points: Points, axis: str = "z", min_m: float = ..., max_m: float = ..., *, keep_inside: bool = True, return_indices: bool = False) -> npt.NDArray[Any]: ...
def level(points: Points, roll_deg: float, pitch_deg: float) -> Points: ...
def generate_pile(shape: str = "typical", points: int = 100_000, *, scale: float = 1.0, roll_deg: float = 3.0, pitch_deg: float = -2.0, pattern: str = "area", sensor_height_m: float = 12.0, fov_deg: float = 70.4, seed: int = 1) -> Points: ...
def perceive(cloud: Union[Points, str, PathLike[str]], *, config: Optional[Union[str, PathLike[str]]] = None, **settings: Any) -> Perception: ...
def perceive_survey(inputs: Union[str, PathLike[str], Sequence[Union[str, PathLike[str]]]], *, tiles_dir: Optional[Union[str, PathLike[str]]] = None, overwrite: bool = False, tile_m: Optional[float] = None, memory_limit_gib: float = 2.0, sample_points: int = 2_000_000, model_cell_m: float = 1.0, work_dir: Optional[Union[str, PathLike[str]]] = None, executor: Optional[Callable[[str, list[str]], list[str]]] = None, config: Optional[Union[str, PathLike[str]]] = None, **settings: Any) -> SurveyPerception: ...
def plan_dig(pile: Union[str, Perception] = "typical", *, profile: Optional[Union[str, PathLike[str]]] = None, seed: int = 1, polish: int = ..., search: str = "bends", init: str = "good-point-set") -> DigPlan: ...
def plan_path(scenario: Union[str, PathLike[str]] = "curve", *, planner: str = "improved-apf", heading_tolerance_deg: float = ...) -> PathPlan: ...
def track(scenario: Union[str, PathLike[str]] = "fig9a", *, controller: str = "fuzzy", noise: Optional[str] = None, seed: int = 1, compare: bool = False, controllers: Optional[Mapping[str, Any]] = None) -> Tracking: ...
def plan_excavate(scenario: Union[str, PathLike[str]] = "paper-over", *, profile: Optional[Union[str, PathLike[str]]] = None) -> Excavation: ...
def study_paths(maps: int = 500, *, seed: int = 1, min_obstacles: int = 3, max_obstacles: int = 12) -> StudySummary: ...
