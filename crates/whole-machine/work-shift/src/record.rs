//! What a shift records: every pass, stand and walk, the timeline, the
//! snapshots for the animation, and the summary with its figures of merit
//! (`summary.json`).

use serde::Serialize;

use autoshovel_core::Pose2;

use crate::world::World;

/// One entry of the timeline.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Simulated time (s).
    pub t_s: f64,
    /// What happened (module docs list the kinds).
    pub kind: &'static str,
    /// The stand (from 1).
    pub stand: usize,
    /// Human text.
    pub message: String,
}

/// One loading cycle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassRecord {
    /// Pass number (from 1).
    pub pass: usize,
    /// Stand number (from 1).
    pub stand: usize,
    /// Start of the dig (s).
    pub t_start_s: f64,
    /// Swing angle dug at (deg).
    pub swing_deg: f64,
    /// Saddle to toe along the dig line, as the machine perceived it (m).
    pub toe_distance_m: f64,
    /// Digging, swinging to the truck, dumping, returning, waiting for a truck (s).
    pub dig_s: f64,
    /// (see `dig_s`)
    pub swing_s: f64,
    /// (see `dig_s`)
    pub dump_s: f64,
    /// (see `dig_s`)
    pub return_s: f64,
    /// (see `dig_s`)
    pub wait_s: f64,
    /// Volume the plan expected, on the perceived pile ([RS eq. 28]) (m³).
    pub planned_m3: f64,
    /// Volume of the same path on the true pile ([RS eq. 28]) (m³) (NaN
    /// where the true pile along the line is too small for the planner's model).
    pub executed_m3: f64,
    /// Volume taken out of the pit (cells under the path) (m³).
    pub dug_m3: f64,
    /// Mass taken (t).
    pub dug_t: f64,
    /// Dug volume over the dipper's capacity.
    pub fill_factor: f64,
    /// Hoist and crowd energy of the dig (J) (on the true pile where known).
    pub hoist_j: f64,
    /// (see `hoist_j`)
    pub crowd_j: f64,
    /// Swing energy, loaded and back (J).
    pub swing_j: f64,
    /// Wall time of perception and of planning (ms).
    pub perceive_ms: f64,
    /// (see `perceive_ms`)
    pub plan_ms: f64,
    /// Wall time of the whole pass, scan to return (ms).
    pub wall_ms: f64,
    /// The tooth path in the world (x, y, height) (m).
    #[serde(skip)]
    pub path: Vec<[f64; 3]>,
    /// The truck loaded (from 1).
    pub truck: usize,
}

/// One walk between stands.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WalkRecord {
    /// From stand, to stand (from 1).
    pub from_stand: usize,
    /// (see `from_stand`)
    pub to_stand: usize,
    /// A V-shaped move (reverse, stop, forward).
    pub v_move: bool,
    /// Planned path length (m).
    pub planned_m: f64,
    /// Distance the crawlers travelled (m).
    pub travelled_m: f64,
    /// Time of the walk (s).
    pub time_s: f64,
    /// Propel energy (J).
    pub energy_j: f64,
    /// Distance of the stop from the stand (m).
    pub final_error_m: f64,
    /// Largest centroid deviation from the planned path (m).
    pub max_deviation_m: f64,
    /// The planned path (x, y) (m).
    #[serde(skip)]
    pub planned: Vec<[f64; 2]>,
    /// The path driven (x, y), true (m).
    #[serde(skip)]
    pub driven: Vec<[f64; 2]>,
    /// The shift's time (s) and the true heading (rad) at each point of `driven`.
    #[serde(skip)]
    pub driven_at: Vec<[f64; 2]>,
}

/// One stand.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StandRecord {
    /// Stand number (from 1).
    pub stand: usize,
    /// The swing axis, true (x, y) (m) and heading (deg).
    pub x_m: f64,
    /// (see `x_m`)
    pub y_m: f64,
    /// (see `x_m`)
    pub heading_deg: f64,
    /// Arrival (s).
    pub t_arrive_s: f64,
    /// Passes dug from it.
    pub passes: usize,
    /// Mass dug from it (t).
    pub dug_t: f64,
    /// Why the machine left it.
    pub left_because: String,
    /// The pit on arrival and on leaving (heights).
    #[serde(skip)]
    pub before: Vec<f64>,
    /// (see `before`)
    #[serde(skip)]
    pub after: Vec<f64>,
}

/// A snapshot of the pit for the animation: heights on a grid of
/// `frame_size` cells at `frame_cell_m`.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Simulated time (s).
    pub t_s: f64,
    /// The machine (true).
    pub pose: Pose2,
    /// Heights (m), x fastest.
    pub z: Vec<f32>,
}

/// The time of a cycle's stages, mean over the passes (s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CycleTimes {
    /// Digging.
    pub dig_s: f64,
    /// Swinging loaded to the truck.
    pub swing_s: f64,
    /// Dumping.
    pub dump_s: f64,
    /// Returning empty.
    pub return_s: f64,
    /// Waiting for a truck.
    pub wait_s: f64,
    /// The whole cycle.
    pub total_s: f64,
}

/// Energy per tonne dug, by drive (kWh/t).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EnergyPerTonne {
    /// Hoist.
    pub hoist: f64,
    /// Crowd.
    pub crowd: f64,
    /// Swing.
    pub swing: f64,
    /// Propel.
    pub propel: f64,
    /// All four.
    pub total: f64,
}

/// The mass balance: what the pit lost, what the trucks got, what the plans expected.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MassBalance {
    /// The pit's volume at the start less at the end, × density (t).
    pub pit_lost_t: f64,
    /// Sum of the passes' dug mass (t).
    pub dug_t: f64,
    /// Sum of the trucks' payloads (t).
    pub dumped_t: f64,
    /// Sum of the plans' expected mass (on the perceived pile) (t).
    pub planned_t: f64,
    /// Sum of the paths' mass on the true pile ([RS eq. 28]), where known (t).
    pub executed_t: f64,
    /// |pit lost − dumped| (t).
    pub error_t: f64,
    /// The tolerance: rounding of the pit's sum, 1e-9 of its mass (t).
    pub tolerance_t: f64,
    /// Whether the balance closes within the tolerance.
    pub closes: bool,
}

/// Fill factor over the passes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FillStats {
    /// Mean.
    pub mean: f64,
    /// Least.
    pub min: f64,
    /// Most.
    pub max: f64,
}

/// The summary of a shift (`summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShiftSummary {
    /// Always "shift".
    pub job: &'static str,
    /// The scenario's name.
    pub scenario: String,
    /// Whether the shift ran to its end (its hours or cycles) rather than
    /// running out of stands.
    pub completed: bool,
    /// Simulated time (h).
    pub hours: f64,
    /// Loading cycles.
    pub passes: usize,
    /// Stands dug from.
    pub stands: usize,
    /// Walks between stands.
    pub walks: usize,
    /// Mass dug (t).
    pub tonnes: f64,
    /// Mass dug over the simulated time (t/h).
    pub tonnes_per_hour: f64,
    /// Mean cycle time by stage.
    pub cycle_time_s: CycleTimes,
    /// Time spent walking (s).
    pub walk_time_s: f64,
    /// Distance walked (m).
    pub walked_m: f64,
    /// Energy per tonne by drive.
    pub energy_kwh_per_t: EnergyPerTonne,
    /// Fill factor per pass.
    pub fill_factor: FillStats,
    /// Pile left in the pit (m³).
    pub volume_left_m3: f64,
    /// The mass balance.
    pub mass_balance: MassBalance,
    /// Safety events (overfill, over-rating, walk stalled).
    pub safety_events: usize,
    /// Events by kind.
    pub events: std::collections::BTreeMap<&'static str, usize>,
    /// The full-size machine: λ, dipper capacity (m³), dig time range (s).
    pub lambda: f64,
    /// (see `lambda`)
    pub dipper_m3: f64,
    /// (see `lambda`)
    pub dig_time_range_s: [f64; 2],
    /// Wall time of the run (ms), per pass (mean, first and last quarter of the passes).
    pub wall_ms: f64,
    /// (see `wall_ms`)
    pub ms_per_pass: f64,
    /// (see `wall_ms`)
    pub ms_per_pass_first_quarter: f64,
    /// (see `wall_ms`)
    pub ms_per_pass_last_quarter: f64,
    /// The models behind the figures of merit, stated.
    pub assumptions: Vec<String>,
}

/// Everything a shift produced.
#[derive(Debug, Clone)]
pub struct ShiftRun {
    /// The summary.
    pub summary: ShiftSummary,
    /// Every pass.
    pub passes: Vec<PassRecord>,
    /// Every stand.
    pub stands: Vec<StandRecord>,
    /// Every walk.
    pub walks: Vec<WalkRecord>,
    /// The timeline.
    pub events: Vec<Event>,
    /// The pit at the start and at the end.
    pub before: World,
    /// (see `before`)
    pub after: World,
    /// Snapshots for the animation, and their grid.
    pub frames: Vec<Frame>,
    /// (x, y) cells of a frame.
    pub frame_size: [usize; 2],
    /// Edge of a frame's cell (m).
    pub frame_cell_m: f64,
}
