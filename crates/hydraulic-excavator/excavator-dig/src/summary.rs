//! The `plan-excavate` job's summary (SPEC §6): the plan's own
//! [`Summary`] and what the report adds — where the
//! scenario and profile came from, every side chosen, the error in %, the
//! whole level-1 plan, the boulders, the detours, the segments and the peak
//! digging force. Every field is read from the [`Setup`] and the
//! [`Excavation`] that produced it.

use serde::Serialize;

use crate::excavation::{Excavation, Level1Report, SegmentReport, Summary};
use crate::preimage::AvoidSide;
use crate::segment::SegmentKind;
use crate::setup::Setup;

/// The job's name in its summary.
pub const JOB: &str = "plan-excavate";

/// The summary of one `plan-excavate` run.
#[derive(Debug, Clone, Serialize)]
pub struct ExcavateSummary {
    /// The job: `plan-excavate`.
    pub job: &'static str,
    /// The plan's figures (scenario name, volumes, contacts, level-1 points, …).
    #[serde(flatten)]
    pub plan: Summary,
    /// The scenario's one line on what it shows.
    pub description: String,
    /// `builtin` or the scenario file's path.
    pub scenario_source: String,
    /// `builtin excavator-15t` or the profile file's path.
    pub profile: String,
    /// 100 · (achieved − target)/target (%).
    pub volume_error_pct: f64,
    /// The side chosen at each contact, in order.
    pub avoid_directions: Vec<AvoidSide>,
    /// How many boulders were met.
    pub contact_count: usize,
    /// Start of the first plan (m).
    pub level1_start_m: [f64; 2],
    /// The first (level-1) plan.
    pub level1: Level1Report,
    /// Every boulder of the scenario.
    pub obstacles: Vec<ObstacleSummary>,
    /// Every detour, in order.
    pub detours: Vec<DetourSummary>,
    /// Every segment executed, in order.
    pub segments: Vec<SegmentSummary>,
    /// Peak |F| on the tooth, contacts included (N).
    pub peak_digging_force_n: f64,
    /// The machine's digging-force rating (N).
    pub max_digging_force_n: f64,
    /// Number of executed samples.
    pub samples: usize,
    /// s, the step of the step search and the search grid (m).
    pub step_m: f64,
    /// h, the dig depth (m).
    pub depth_m: f64,
    /// Whether the step search bisected inside its last step.
    pub refine_volume: bool,
}

/// One boulder of the scenario.
#[derive(Debug, Clone, Serialize)]
pub struct ObstacleSummary {
    /// Envelope centre (m).
    pub center_m: [f64; 2],
    /// Envelope radius (m).
    pub radius_m: f64,
    /// Its volume across the bucket's width (m³).
    pub volume_m3: f64,
    /// True when the tooth met it.
    pub met: bool,
}

/// One detour round a boulder, with the segment that executed it.
#[derive(Debug, Clone, Serialize)]
pub struct DetourSummary {
    /// Index into the contacts.
    pub contact: usize,
    /// The side passed.
    pub side: AvoidSide,
    /// The goal line x (m).
    pub goal_x_m: f64,
    /// Least distance of the smoothed detour from the envelope met (null
    /// when not finite) (m).
    pub clearance_m: f64,
    /// Start of its segment (s).
    pub t_start_s: f64,
    /// End of its segment, or the contact that cut it short (s).
    pub t_end_s: f64,
    /// False when a contact cut it short.
    pub completed: bool,
    /// Waypoints of the forward search's grid path.
    pub waypoints: usize,
    /// |P|: free points classified.
    pub free_points: usize,
    /// |Q|: colliding points classified.
    pub blocked_points: usize,
    /// Points expanded.
    pub expanded: usize,
    /// Volume counted when it was planned (m³).
    pub volume_before_replan_m3: f64,
}

/// One executed (or interrupted) segment.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentSummary {
    /// Its role.
    pub kind: SegmentKind,
    /// Start (s).
    pub t_start_s: f64,
    /// End, or the contact that cut it short (s).
    pub t_end_s: f64,
    /// Start point (m).
    pub from_m: [f64; 2],
    /// Planned end point (m).
    pub to_m: [f64; 2],
    /// Volume planned for it (none for a detour) (m³).
    pub planned_volume_m3: Option<f64>,
    /// False when a contact cut it short.
    pub completed: bool,
}

impl ExcavateSummary {
    /// The summary of `ex`, planned from `setup`.
    pub fn new(setup: &Setup, ex: &Excavation) -> Self {
        let sc = &setup.scenario;
        let width_m = setup.profile.bucket.width_m;
        Self {
            job: JOB,
            plan: ex.summary(),
            description: sc.description.clone(),
            scenario_source: setup.scenario_source.clone(),
            profile: setup.profile_name.clone(),
            volume_error_pct: 100.0 * ex.volume_error(),
            avoid_directions: ex.contacts.iter().map(|c| c.decision).collect(),
            contact_count: ex.contacts.len(),
            level1_start_m: ex.level1.start_m,
            level1: ex.level1.clone(),
            obstacles: ex
                .obstacles
                .iter()
                .enumerate()
                .map(|(i, e)| ObstacleSummary {
                    center_m: e.center_m,
                    radius_m: e.radius_m,
                    volume_m3: e.area_m2() * width_m,
                    met: ex.met(i),
                })
                .collect(),
            detours: ex
                .detour_segments()
                .map(|(d, g)| DetourSummary {
                    contact: d.contact,
                    side: d.side,
                    goal_x_m: d.goal_x_m,
                    clearance_m: d.clearance_m,
                    t_start_s: g.t_start_s,
                    t_end_s: g.t_end_s,
                    completed: g.completed,
                    waypoints: d.search.waypoints.len(),
                    free_points: d.search.free_points,
                    blocked_points: d.search.blocked_points,
                    expanded: d.search.expanded,
                    volume_before_replan_m3: d.volume_before_replan_m3,
                })
                .collect(),
            segments: ex.segments.iter().map(SegmentSummary::from).collect(),
            peak_digging_force_n: ex.peak_digging_force_n(),
            max_digging_force_n: setup.profile.force.max_digging_force_n,
            samples: ex.samples.len(),
            step_m: sc.dig.step_m,
            depth_m: sc.dig.depth_m,
            refine_volume: sc.planner.refine_volume,
        }
    }
}

impl From<&SegmentReport> for SegmentSummary {
    fn from(g: &SegmentReport) -> Self {
        Self {
            kind: g.kind,
            t_start_s: g.t_start_s,
            t_end_s: g.t_end_s,
            from_m: g.from_m,
            to_m: g.to_m,
            planned_volume_m3: g.planned_volume_m3,
            completed: g.completed,
        }
    }
}
