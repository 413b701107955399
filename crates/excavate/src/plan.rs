//! The two-level planner run against the soil simulator (paper §2.2, Fig. 4).
//!
//! 1. Level 1 plans the dig for the target volume ([`crate::level1`]).
//! 2. The simulator executes the plan step by step ([`crate::simulate`]).
//! 3. On a contact, preimage planning picks the side from γ
//!    ([`crate::preimage`]); the forward search finds a way round on that side
//!    ([`crate::search`]), smoothed and checked ([`crate::smooth`]).
//! 4. The boulder now counts as dug (the paper: "将障碍物体积作为当前挖土量的一部分")
//!    and the rest is re-planned with level 1 from the detour's end to the
//!    remaining volume: if the first half is not done yet, down to the dig
//!    depth holding what the first half still lacks, then up to the ground
//!    holding the rest; otherwise straight up holding the rest. Re-planned
//!    paths keep out of every known envelope; where they cannot, the detour is
//!    extended one grid step further and the re-plan tried again.
//! 5. Execution resumes; each new contact repeats 3–4.
//!
//! # Counting the volume
//! achieved = b·(area between the ground and the executed tip path, [HE eq. 2], less
//! the envelopes lying inside that area) + b·π r² for every boulder met or lying
//! inside that area. A boulder passed under lies inside the dug area and is
//! counted once, as rock; a boulder passed over lies below the path and counts
//! because the paper counts it. The soil part alone is reported as well.

use std::collections::VecDeque;
use std::time::Instant;

use autoshovel_core::{config, Vec2};
use serde::Serialize;

use crate::dynamics::Dynamics;
use crate::error::{ExcavateError, Result};
use crate::ground::Ground;
use crate::kinematics::{Backhoe, Joints};
use crate::level1::{plan_level1, EndLevel, Level1Plan, StepFound, StepSearch};
use crate::obstacle::Envelope;
use crate::preimage::{decide, gamma_rad, AvoidSide};
use crate::profile::MachineProfile;
use crate::scenario::{Scenario, MAX_SIM_STEPS, SIM_STEP_BYTES};
use crate::search::{forward_search, SearchParams, SearchPath};
use crate::segment::{Motion, MotionState, Segment, SegmentKind};
use crate::simulate::{Contact, SoilSim};
use crate::smooth::smooth_detour;
use crate::volume::{disc_area_below, strip, swept_area};

/// How many grid steps past the boulder a detour may be extended to let the
/// re-plan clear it.
const MAX_DETOUR_EXTENSION: usize = 12;

/// One boulder met.
#[derive(Debug, Clone, Serialize)]
pub struct ContactReport {
    /// Index of the boulder in the scenario.
    pub obstacle: usize,
    /// Time [s].
    pub t_s: f64,
    /// Contact point [m].
    pub point_m: [f64; 2],
    /// V_c, tip velocity at the contact [m/s].
    pub velocity_m_s: [f64; 2],
    /// F_f, the boulder's push on the tooth [N].
    pub force_n: [f64; 2],
    /// γ, clockwise from V_c to F_f (see [`crate::preimage`]) [deg].
    pub gamma_deg: f64,
    /// The preimage rule's choice.
    pub decision: AvoidSide,
}

/// One executed sample.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Time [s].
    pub t_s: f64,
    /// Tooth tip [m].
    pub tip_m: [f64; 2],
    /// θ₁, θ₂, θ₃ [rad].
    pub joints_rad: [f64; 3],
    /// Joint rates [rad/s].
    pub joint_rates_rad_s: [f64; 3],
    /// φ = θ₁ + θ₂ + θ₃ [rad].
    pub attitude_rad: f64,
    /// Joint torques from the Lagrange dynamics [N·m].
    pub torques_nm: [f64; 3],
    /// Digging resistance on the tooth (soil, plus the boulder at a contact) [N].
    pub digging_force_n: [f64; 2],
    /// Its magnitude [N].
    pub digging_force_magnitude_n: f64,
    /// Soil carried in the bucket [kg].
    pub load_kg: f64,
    /// [HE eq. 2] volume swept so far (soil and any boulder inside it) [m³].
    pub swept_volume_m3: f64,
    /// Index into [`Excavation::segments`].
    pub segment: usize,
    /// The segment's role.
    pub kind: SegmentKind,
    /// True for the sample at a contact.
    pub contact: bool,
}

/// One executed (or interrupted) segment.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentReport {
    /// Its role.
    pub kind: SegmentKind,
    /// Start [s].
    pub t_start_s: f64,
    /// End, or the contact that cut it short [s].
    pub t_end_s: f64,
    /// Planned duration [s].
    pub planned_duration_s: f64,
    /// Start point [m].
    pub from_m: [f64; 2],
    /// Planned end point [m].
    pub to_m: [f64; 2],
    /// Volume planned for it ([HE eq. 2]; none for a detour) [m³].
    pub planned_volume_m3: Option<f64>,
    /// n of the step search that placed its end (none for a detour).
    pub steps: Option<usize>,
    /// False when a contact cut it short.
    pub completed: bool,
}

/// A detour round a boulder.
#[derive(Debug, Clone, Serialize)]
pub struct DetourReport {
    /// Index into [`Excavation::contacts`].
    pub contact: usize,
    /// The side passed.
    pub side: AvoidSide,
    /// The goal line x [m].
    pub goal_x_m: f64,
    /// The forward search's grid path and its P/Q counts.
    pub search: SearchPath,
    /// The smoothed detour, densely sampled [m].
    pub smoothed_m: Vec<[f64; 2]>,
    /// Least distance of the smoothed detour from the envelope met, past its
    /// first tenth (it starts on the rim) [m].
    pub clearance_m: f64,
    /// Volume counted when it was planned (swept so far and boulders) [m³].
    pub volume_before_replan_m3: f64,
    /// The re-planned path after the detour, sampled in time [m].
    pub replanned_m: Vec<[f64; 2]>,
}

/// The level-1 plan made before any contact.
#[derive(Debug, Clone, Serialize)]
pub struct Level1Report {
    /// (x_begin, ground) [m].
    pub start_m: [f64; 2],
    /// (x_mid, −h) [m].
    pub mid_m: [f64; 2],
    /// (x_end, ground) [m].
    pub end_m: [f64; 2],
    /// Volume of the first half [m³].
    pub first_half_m3: f64,
    /// Volume of the second half [m³].
    pub second_half_m3: f64,
    /// n of the midpoint.
    pub mid_steps: usize,
    /// n of the end point.
    pub end_steps: usize,
    /// Volume the midpoint's last step changed [m³].
    pub first_step_volume_m3: f64,
    /// Volume the end point's last step changed [m³].
    pub second_step_volume_m3: f64,
    /// Durations of descent and rise [s].
    pub durations_s: [f64; 2],
    /// The planned tip path, sampled in time [m] (for plots and CSV; not
    /// in summaries).
    #[serde(skip_serializing)]
    pub path_m: Vec<[f64; 2]>,
}

/// Everything a plan produced: to plot and to summarise.
#[derive(Debug, Clone, Serialize)]
pub struct Excavation {
    /// Scenario name.
    pub scenario: String,
    /// The ground line, for plots.
    pub ground: Ground,
    /// Every boulder of the scenario (the planner learns them by contact), for plots.
    pub obstacles: Vec<Envelope>,
    /// V [m³].
    pub target_volume_m3: f64,
    /// Dug, soil and boulders (module docs) [m³].
    pub achieved_volume_m3: f64,
    /// Soil alone [m³].
    pub soil_volume_m3: f64,
    /// Boulders counted as dug [m³].
    pub obstacle_volume_m3: f64,
    /// The side chosen at the first contact, if any.
    pub avoid_direction: Option<AvoidSide>,
    /// Every contact, in order.
    pub contacts: Vec<ContactReport>,
    /// The first plan.
    pub level1: Level1Report,
    /// Every segment executed, in order.
    pub segments: Vec<SegmentReport>,
    /// Every detour, in order.
    pub detours: Vec<DetourReport>,
    /// The executed motion.
    pub samples: Vec<Sample>,
    /// Length of the dig [s].
    pub duration_s: f64,
    /// Least signed distance of the executed tip from any envelope (0 when
    /// touching at a contact; never negative) [m]; none without boulders.
    pub min_envelope_distance_m: Option<f64>,
    /// max over consecutive samples and joints of |Δθ| / (θ̇_max·Δt): at most 1
    /// means no jump beyond the speed limits.
    pub max_joint_step_ratio: f64,
    /// Peak |τ| per joint, the stall at a contact included [N·m].
    pub peak_torques_nm: [f64; 3],
    /// Peak soil resistance (contacts excluded) [N].
    pub peak_soil_force_n: f64,
    /// Wall time of planning and simulation [ms].
    pub plan_time_ms: f64,
}

/// The summary the CLI prints (SPEC §6).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// V [m³].
    pub target_volume_m3: f64,
    /// Dug [m³].
    pub achieved_volume_m3: f64,
    /// (achieved − target)/target.
    pub volume_error: f64,
    /// Soil alone [m³].
    pub soil_volume_m3: f64,
    /// Boulders counted [m³].
    pub obstacle_volume_m3: f64,
    /// Contacts.
    pub contacts: Vec<ContactReport>,
    /// First contact's side (`over`, `under`), or none.
    pub avoid_direction: Option<AvoidSide>,
    /// Dig duration [s].
    pub duration_s: f64,
    /// Midpoint and end point of the first plan [m].
    pub level1_mid_m: [f64; 2],
    /// End point of the first plan [m].
    pub level1_end_m: [f64; 2],
    /// Where the dig actually ended [m].
    pub final_tip_m: [f64; 2],
    /// See [`Excavation::min_envelope_distance_m`].
    pub min_envelope_distance_m: Option<f64>,
    /// See [`Excavation::max_joint_step_ratio`].
    pub max_joint_step_ratio: f64,
    /// Peak |τ| per joint, the stall at a contact included [N·m].
    pub peak_torques_nm: [f64; 3],
    /// Peak soil resistance [N].
    pub peak_soil_force_n: f64,
    /// Wall time [ms].
    pub plan_time_ms: f64,
}

impl Excavation {
    /// The summary (SPEC §6 `plan-excavate`).
    pub fn summary(&self) -> Summary {
        let last = self.samples.last().map_or([f64::NAN; 2], |s| s.tip_m);
        Summary {
            scenario: self.scenario.clone(),
            target_volume_m3: self.target_volume_m3,
            achieved_volume_m3: self.achieved_volume_m3,
            volume_error: self.volume_error(),
            soil_volume_m3: self.soil_volume_m3,
            obstacle_volume_m3: self.obstacle_volume_m3,
            contacts: self.contacts.clone(),
            avoid_direction: self.avoid_direction,
            duration_s: self.duration_s,
            level1_mid_m: self.level1.mid_m,
            level1_end_m: self.level1.end_m,
            final_tip_m: last,
            min_envelope_distance_m: self.min_envelope_distance_m,
            max_joint_step_ratio: self.max_joint_step_ratio,
            peak_torques_nm: self.peak_torques_nm,
            peak_soil_force_n: self.peak_soil_force_n,
            plan_time_ms: self.plan_time_ms,
        }
    }

    /// (achieved − target)/target.
    pub fn volume_error(&self) -> f64 {
        (self.achieved_volume_m3 - self.target_volume_m3) / self.target_volume_m3
    }

    /// The executed tip path [m].
    pub fn executed_path(&self) -> Vec<[f64; 2]> {
        self.samples.iter().map(|s| s.tip_m).collect()
    }

    /// The first (level-1) plan's tip path, before any contact [m].
    pub fn planned_path(&self) -> &[[f64; 2]] {
        &self.level1.path_m
    }

    /// The executed sample at a contact (the contact sample nearest in time).
    pub fn contact_sample(&self, c: &ContactReport) -> Option<&Sample> {
        self.samples
            .iter()
            .filter(|s| s.contact)
            .min_by(|a, b| (a.t_s - c.t_s).abs().total_cmp(&(b.t_s - c.t_s).abs()))
    }

    /// Peak |F| on the tooth over the dig, contacts included (0 without samples) [N].
    pub fn peak_digging_force_n(&self) -> f64 {
        self.samples
            .iter()
            .map(|s| s.digging_force_magnitude_n)
            .fold(0.0, f64::max)
    }

    /// True when the tooth met boulder `index` of the scenario.
    pub fn met(&self, index: usize) -> bool {
        self.contacts.iter().any(|c| c.obstacle == index)
    }

    /// Each detour with the segment that executed it (the n-th detour
    /// segment belongs to the n-th detour).
    pub fn detour_segments(&self) -> impl Iterator<Item = (&DetourReport, &SegmentReport)> {
        let segments = self
            .segments
            .iter()
            .filter(|g| g.kind == SegmentKind::Detour);
        self.detours.iter().zip(segments)
    }
}

/// Plan and execute a scenario on a machine; the wall time goes into
/// [`Excavation::plan_time_ms`].
pub fn excavate(scenario: &Scenario, profile: &MachineProfile) -> Result<Excavation> {
    let started = Instant::now();
    let mut run = Run::new(scenario, profile);
    let mut ex = run.execute()?;
    ex.plan_time_ms = started.elapsed().as_secs_f64() * 1e3;
    Ok(ex)
}

/// The state of one pass.
struct Run<'a> {
    sc: &'a Scenario,
    machine: Backhoe,
    dynamics: Dynamics,
    max_force_n: f64,
    width_m: f64,
    attitude: [f64; 3],
    known: Vec<bool>,
    first_half_done: bool,
    t_s: f64,
    tips: Vec<Vec2>,
    swept_area: f64,
    samples: Vec<Sample>,
    segments: Vec<SegmentReport>,
    contacts: Vec<ContactReport>,
    detours: Vec<DetourReport>,
    peak_soil_force_n: f64,
}

impl<'a> Run<'a> {
    fn new(sc: &'a Scenario, profile: &MachineProfile) -> Self {
        Self {
            sc,
            machine: Backhoe::new(profile),
            dynamics: Dynamics::new(profile),
            max_force_n: profile.force.max_digging_force_n,
            width_m: profile.bucket.width_m,
            attitude: sc.level1_request().attitude_rad,
            known: vec![false; sc.obstacles.len()],
            first_half_done: false,
            t_s: 0.0,
            tips: Vec::new(),
            swept_area: 0.0,
            samples: Vec::new(),
            segments: Vec::new(),
            contacts: Vec::new(),
            detours: Vec::new(),
            peak_soil_force_n: 0.0,
        }
    }

    fn ground(&self) -> &'a Ground {
        &self.sc.ground
    }

    fn known_envelopes(&self) -> Vec<Envelope> {
        self.sc
            .obstacles
            .iter()
            .zip(&self.known)
            .filter(|(_, k)| **k)
            .map(|(e, _)| *e)
            .collect()
    }

    fn step_search<'b>(&'b self, known: &'b [Envelope]) -> StepSearch<'b> {
        self.sc.step_search(&self.machine, self.width_m, known)
    }

    fn sample_path(&self, segments: &[Segment]) -> Vec<[f64; 2]> {
        let dt = self.sc.planner.dt_s;
        let mut out = Vec::new();
        for seg in segments {
            let n = (seg.duration_s() / dt).ceil().max(1.0) as usize;
            let tips = seg.sample_tips(&self.machine, n);
            let skip = usize::from(!out.is_empty());
            out.extend(tips.into_iter().skip(skip).map(|p| [p.x, p.y]));
        }
        out
    }

    fn execute(&mut self) -> Result<Excavation> {
        let sc = self.sc;
        let d = &sc.dig;
        let start = Vec2::new(d.start_x_m, self.ground().height(d.start_x_m));
        for (index, e) in sc.obstacles.iter().enumerate() {
            if e.contains(start) {
                return Err(ExcavateError::ObstacleEnclosesStart {
                    index,
                    center_m: e.center_m,
                    radius_m: e.radius_m,
                    start_m: [start.x, start.y],
                });
            }
        }
        let req = self.sc.level1_request();
        let plan = plan_level1(&self.step_search(&[]), &req)?;
        let mut pending: VecDeque<PlannedSegment> = plan_segments(&plan);
        let planned_s = pending.iter().map(|ps| ps.segment.duration_s()).sum();
        self.check_steps(planned_s, "the level-1 plan")?;
        let level1 = self.level1_report(&plan);

        // The first sample, at rest at the start.
        let first = plan.first.segment.state(&self.machine, 0.0);
        self.tips.push(first.tip);
        self.push_sample(0.0, &first, Vec2::zeros(), 0, SegmentKind::Descent, false);

        let machine = self.machine.clone();
        while let Some(ps) = pending.pop_front() {
            let seg_index = self.segments.len();
            let seg = &ps.segment;
            let from = seg.tip(&self.machine, 0.0);
            let to = seg.tip(&self.machine, seg.duration_s());
            let sim = SoilSim {
                machine: &machine,
                ground: &sc.ground,
                soil: &sc.soil,
                obstacles: &sc.obstacles,
                bucket_width_m: self.width_m,
                max_force_n: self.max_force_n,
            };
            let after = self.contacts.len();
            self.check_steps(
                self.t_s + seg.duration_s(),
                &format!("the dig after {after} contact(s)"),
            )?;
            let run = sim.advance(seg, sc.planner.dt_s, &self.known);
            let t0 = self.t_s;
            let n = run.states.len();
            for (k, (t, state)) in run.states.iter().enumerate() {
                let is_contact = run.contact.is_some() && k + 1 == n;
                let mut force = sim.resistance(state);
                let soil_force = force.norm();
                if !is_contact {
                    self.peak_soil_force_n = self.peak_soil_force_n.max(soil_force);
                    if soil_force > self.max_force_n {
                        return Err(ExcavateError::SoilTooHard {
                            t_s: t0 + t,
                            force_n: soil_force,
                            max_n: self.max_force_n,
                            depth_m: self.ground().depth(state.tip.x, state.tip.y),
                        });
                    }
                }
                if is_contact {
                    force += run.contact.as_ref().map_or(Vec2::zeros(), |c| c.force);
                }
                let prev = *self.tips.last().expect("the start is in");
                self.swept_area += strip(self.ground(), prev, state.tip); // [HE eq. 2]
                self.tips.push(state.tip);
                self.push_sample(t0 + t, state, force, seg_index, seg.kind, is_contact);
            }
            let t_end = t0 + run.states.last().map_or(0.0, |(t, _)| *t);
            self.segments.push(SegmentReport {
                kind: seg.kind,
                t_start_s: t0,
                t_end_s: t_end,
                planned_duration_s: seg.duration_s(),
                from_m: [from.x, from.y],
                to_m: [to.x, to.y],
                planned_volume_m3: ps.volume_m3,
                steps: ps.steps,
                completed: run.contact.is_none(),
            });
            self.t_s = t_end;
            match run.contact {
                None => {
                    if seg.kind == SegmentKind::Descent {
                        self.first_half_done = true;
                    }
                }
                Some(c) => {
                    if self.contacts.len() >= sc.planner.max_contacts {
                        return Err(ExcavateError::TooManyContacts {
                            max: sc.planner.max_contacts,
                        });
                    }
                    let gamma = gamma_rad(c.velocity, c.force);
                    let side = decide(gamma);
                    self.contacts.push(ContactReport {
                        obstacle: c.obstacle,
                        t_s: t_end,
                        point_m: [c.point.x, c.point.y],
                        velocity_m_s: [c.velocity.x, c.velocity.y],
                        force_n: [c.force.x, c.force.y],
                        gamma_deg: gamma.to_degrees(),
                        decision: side,
                    });
                    self.known[c.obstacle] = true;
                    pending = self.replan(&c, side)?.into();
                }
            }
        }
        self.finish(level1)
    }

    /// Detour and re-plan after a contact.
    fn replan(&mut self, c: &Contact, side: AvoidSide) -> Result<Vec<PlannedSegment>> {
        let sc = self.sc;
        let met = sc.obstacles[c.obstacle];
        let known = self.known_envelopes();
        let attitude = c.state.q.sum();
        let params = SearchParams {
            step_m: sc.dig.step_m,
            clearance_m: sc.planner.clearance_m,
            window_m: sc.planner.search_window_m,
        };
        let big_r = met.radius_m + params.clearance_m;
        let impassable = |why: String| ExcavateError::ObstacleImpassable {
            index: c.obstacle,
            side,
            contact_m: [c.point.x, c.point.y],
            why,
        };
        let mut first_err: Option<ExcavateError> = None;
        for extra in 1..=MAX_DETOUR_EXTENSION {
            let goal_x = met.center().x - big_r - extra as f64 * params.step_m;
            let path = forward_search(
                &self.machine,
                attitude,
                c.point,
                c.normal,
                &met,
                side,
                &known,
                goal_x,
                &params,
            )
            .map_err(|f| impassable(f.why))?;
            let detour = smooth_detour(
                &self.machine,
                c.point,
                &path.waypoints,
                attitude,
                &known,
                sc.planner.speed_fraction,
                sc.planner.min_segment_time_s,
            )
            .map_err(impassable)?;
            let seg = Segment {
                kind: SegmentKind::Detour,
                motion: Motion::Detour(detour),
            };
            // Volume so far: executed path plus the detour.
            let det_tips = seg.sample_tips(&self.machine, sc.planner.trapezoids);
            let mut path_so_far = self.tips.clone();
            path_so_far.extend(det_tips.iter().skip(1));
            let area = self.swept_area + swept_area(self.ground(), &det_tips); // [HE eq. 2]
            let (soil, rock) = self.counted(&path_so_far, area);
            let current = soil + rock;
            let end = *det_tips.last().expect("samples");
            let end_q = seg.end_joints(&self.machine);
            match self.plan_rest(end, &end_q, current, &known) {
                Ok(rest) => {
                    let mut out = vec![PlannedSegment {
                        segment: seg,
                        volume_m3: None,
                        steps: None,
                    }];
                    let first_tenth = det_tips.len() / 10;
                    let clearance = det_tips
                        .iter()
                        .skip(first_tenth.max(1))
                        .map(|p| met.signed_distance(*p))
                        .fold(f64::INFINITY, f64::min);
                    let smoothed = match &out[0].segment.motion {
                        Motion::Detour(d) => (0..=200)
                            .map(|k| {
                                let p = d.spline.point(k as f64 / 200.0);
                                [p.x, p.y]
                            })
                            .collect(),
                        Motion::Joint(_) => Vec::new(),
                    };
                    let rest_segments: Vec<Segment> =
                        rest.iter().map(|r| r.segment.clone()).collect();
                    self.detours.push(DetourReport {
                        contact: self.contacts.len() - 1,
                        side,
                        goal_x_m: goal_x,
                        search: path,
                        smoothed_m: smoothed,
                        clearance_m: clearance,
                        volume_before_replan_m3: current,
                        replanned_m: self.sample_path(&rest_segments),
                    });
                    out.extend(rest);
                    return Ok(out);
                }
                Err(e) => {
                    if first_err.is_none() {
                        first_err = Some(e);
                    }
                }
            }
        }
        Err(first_err.expect("at least one attempt"))
    }

    /// Level 1 from a detour's end to the remaining volume (module docs).
    fn plan_rest(
        &mut self,
        from: Vec2,
        from_q: &Joints,
        current_m3: f64,
        known: &[Envelope],
    ) -> Result<Vec<PlannedSegment>> {
        let d = &self.sc.dig;
        let search = self.step_search(known);
        let remaining = d.target_volume_m3 - current_m3;
        let first_lacks = 0.5 * d.target_volume_m3 - current_m3;
        let depth_here = self.ground().depth(from.x, from.y);
        let mut out = Vec::new();
        let (mut p, mut q, mut left) = (from, *from_q, remaining);
        if !self.first_half_done && first_lacks > 0.0 && depth_here < d.depth_m {
            let down = search.search(
                p,
                &q,
                EndLevel::Depth,
                d.depth_m,
                self.attitude[1],
                first_lacks,
                SegmentKind::Descent,
                "the re-planned first half (detour end to the dig depth)",
            )?;
            p = down.point;
            q = down.joints;
            left -= down.volume_m3;
            out.push(PlannedSegment::from_found(down));
        }
        let up = search.search(
            p,
            &q,
            EndLevel::Ground,
            d.depth_m,
            self.attitude[2],
            left,
            SegmentKind::Rise,
            "the re-planned rest (up to the ground)",
        )?;
        out.push(PlannedSegment::from_found(up));
        if out.len() == 1 {
            // Going straight up: the first half is over.
            self.first_half_done = true;
        }
        Ok(out)
    }

    /// (soil, boulders) volume [m³] of a path with [HE eq. 2] area `area` (module docs).
    fn counted(&self, path: &[Vec2], area: f64) -> (f64, f64) {
        let g = self.ground();
        let mut soil_area = area;
        let mut rock = 0.0;
        for (i, e) in self.sc.obstacles.iter().enumerate() {
            let c = e.center();
            let probe = Vec2::new(c.x, c.y.min(g.height(c.x) - 1e-6));
            let inside = e.contains(probe) && inside_dug_region(g, path, probe);
            if inside {
                soil_area -= disc_area_below(g, c, e.radius_m);
            }
            if inside || self.known[i] {
                rock += e.area_m2() * self.width_m;
            }
        }
        (soil_area * self.width_m, rock) // [HE eq. 2]: area × h_b
    }

    fn push_sample(
        &mut self,
        t_s: f64,
        state: &MotionState,
        force: Vec2,
        segment: usize,
        kind: SegmentKind,
        contact: bool,
    ) {
        let load_kg = (self.swept_area * self.width_m).max(0.0) * self.sc.soil.density_kg_m3;
        let tau = self
            .dynamics
            .inverse_dynamics(&state.q, &state.qd, &state.qdd, load_kg, force);
        self.samples.push(Sample {
            t_s,
            tip_m: [state.tip.x, state.tip.y],
            joints_rad: [state.q[0], state.q[1], state.q[2]],
            joint_rates_rad_s: [state.qd[0], state.qd[1], state.qd[2]],
            attitude_rad: state.q.sum(),
            torques_nm: [tau[0], tau[1], tau[2]],
            digging_force_n: [force.x, force.y],
            digging_force_magnitude_n: force.norm(),
            load_kg,
            swept_volume_m3: self.swept_area * self.width_m,
            segment,
            kind,
            contact,
        });
    }

    /// Refuses a dig of `duration_s` that would take more than
    /// [`MAX_SIM_STEPS`] simulator steps, before taking them.
    fn check_steps(&self, duration_s: f64, what: &str) -> Result<()> {
        let dt = self.sc.planner.dt_s;
        let steps = duration_s / dt;
        if steps <= MAX_SIM_STEPS {
            return Ok(());
        }
        Err(ExcavateError::TooMuchWork {
            key: "[planner] dt_s",
            value: config::short(dt),
            estimate: format!(
                "{what} takes {duration_s:.1} s, about {} simulator steps ({})",
                config::approx(steps),
                config::bytes(steps * SIM_STEP_BYTES)
            ),
            ceiling: format!(
                "{} steps (here dt_s ≥ {} s)",
                config::approx(MAX_SIM_STEPS),
                config::approx(duration_s / MAX_SIM_STEPS)
            ),
        })
    }

    fn level1_report(&self, plan: &Level1Plan) -> Level1Report {
        let segs = plan.segments();
        Level1Report {
            start_m: [plan.start.x, plan.start.y],
            mid_m: [plan.mid.x, plan.mid.y],
            end_m: [plan.end.x, plan.end.y],
            first_half_m3: plan.first.volume_m3,
            second_half_m3: plan.second.volume_m3,
            mid_steps: plan.first.steps,
            end_steps: plan.second.steps,
            first_step_volume_m3: plan.first.step_volume_m3,
            second_step_volume_m3: plan.second.step_volume_m3,
            durations_s: [segs[0].duration_s(), segs[1].duration_s()],
            path_m: self.sample_path(&segs),
        }
    }

    fn finish(&mut self, level1: Level1Report) -> Result<Excavation> {
        let sc = self.sc;
        // Never return a path through an obstacle.
        let mut min_dist: Option<f64> = None;
        for s in &self.samples {
            let p = Vec2::new(s.tip_m[0], s.tip_m[1]);
            for (index, e) in sc.obstacles.iter().enumerate() {
                let d = e.signed_distance(p);
                if d < -1e-9 {
                    return Err(ExcavateError::PathThroughObstacle {
                        index,
                        at_m: s.tip_m,
                    });
                }
                min_dist = Some(min_dist.map_or(d, |m: f64| m.min(d)));
            }
        }
        let speed = self.machine.limits.speed_rad_s;
        let mut ratio = 0.0f64;
        for w in self.samples.windows(2) {
            let dt = w[1].t_s - w[0].t_s;
            if dt <= 1e-12 {
                continue;
            }
            for (i, limit) in speed.iter().enumerate() {
                let r = (w[1].joints_rad[i] - w[0].joints_rad[i]).abs() / (limit * dt);
                ratio = ratio.max(r);
            }
        }
        let mut peak = [0.0f64; 3];
        for s in &self.samples {
            for (p, t) in peak.iter_mut().zip(s.torques_nm) {
                *p = p.max(t.abs());
            }
        }
        let (soil, rock) = self.counted(&self.tips, self.swept_area);
        Ok(Excavation {
            scenario: sc.name.clone(),
            ground: sc.ground.clone(),
            obstacles: sc.obstacles.clone(),
            target_volume_m3: sc.dig.target_volume_m3,
            achieved_volume_m3: soil + rock,
            soil_volume_m3: soil,
            obstacle_volume_m3: rock,
            avoid_direction: self.contacts.first().map(|c| c.decision),
            contacts: self.contacts.clone(),
            level1,
            segments: self.segments.clone(),
            detours: self.detours.clone(),
            samples: std::mem::take(&mut self.samples),
            duration_s: self.t_s,
            min_envelope_distance_m: min_dist,
            max_joint_step_ratio: ratio,
            peak_torques_nm: peak,
            peak_soil_force_n: self.peak_soil_force_n,
            plan_time_ms: 0.0,
        })
    }
}

/// A segment with what its planning said about it.
struct PlannedSegment {
    segment: Segment,
    volume_m3: Option<f64>,
    steps: Option<usize>,
}

impl PlannedSegment {
    fn from_found(f: StepFound) -> Self {
        Self {
            segment: f.segment,
            volume_m3: Some(f.volume_m3),
            steps: Some(f.steps),
        }
    }
}

fn plan_segments(plan: &Level1Plan) -> VecDeque<PlannedSegment> {
    [plan.first.clone(), plan.second.clone()]
        .into_iter()
        .map(PlannedSegment::from_found)
        .collect()
}

/// True when `p` lies in the region between the ground and the tip path
/// (closed by the vertical at the path's last point and the ground back to
/// its first), by the crossing-number test.
fn inside_dug_region(ground: &Ground, path: &[Vec2], p: Vec2) -> bool {
    let (Some(first), Some(last)) = (path.first(), path.last()) else {
        return false;
    };
    let mut poly: Vec<Vec2> = path.to_vec();
    poly.push(Vec2::new(last.x, ground.height(last.x)));
    let (lo, hi) = (last.x.min(first.x), last.x.max(first.x));
    let mut between: Vec<Vec2> = ground
        .points
        .iter()
        .filter(|v| v[0] > lo && v[0] < hi)
        .map(|v| Vec2::new(v[0], v[1]))
        .collect();
    if last.x > first.x {
        between.reverse();
    }
    poly.extend(between);
    poly.push(Vec2::new(first.x, ground.height(first.x)));
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if x > p.x {
                inside = !inside;
            }
        }
    }
    inside
}
