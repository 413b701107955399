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
use crate::estimate::{BoulderEstimate, Touch};
use crate::ground::Ground;
use crate::kinematics::{Backhoe, Joints};
use crate::level1::Level1Plan;
use crate::obstacle::Envelope;
use crate::planner::{PlannedSegment, Planner};
use crate::preimage::AvoidSide;
use crate::profile::MachineProfile;
use crate::scenario::{Scenario, MAX_SIM_STEPS, SIM_STEP_BYTES};
use crate::search::SearchPath;
use crate::segment::{MotionState, SegmentKind};
use crate::simulate::{SoilSim, TorqueSensor};
use crate::volume::{counted_volume, strip};

/// One boulder met.
#[derive(Debug, Clone, Serialize)]
pub struct ContactReport {
    /// Index of the boulder in the scenario.
    pub obstacle: usize,
    /// Time (s).
    pub t_s: f64,
    /// Contact point (m).
    pub point_m: [f64; 2],
    /// V_c, tip velocity at the contact (m/s).
    pub velocity_m_s: [f64; 2],
    /// F_f, the boulder's push on the tooth, in the simulator (N).
    pub force_n: [f64; 2],
    /// F̂, the force the planner estimated from the measured torque jump (N).
    pub measured_force_n: [f64; 2],
    /// n̂, the rock's normal the planner estimated from F̂.
    pub estimated_normal: [f64; 2],
    /// The envelope's true outward normal there (simulator).
    pub true_normal: [f64; 2],
    /// γ from V_c to F̂ as the planner reads it (see [`crate::preimage`]) (deg).
    pub gamma_deg: f64,
    /// The preimage rule's choice.
    pub decision: AvoidSide,
    /// Index of the planner's boulder estimate this touch refined or started.
    pub estimate: usize,
    /// That estimate after the touch: the envelope planned round.
    pub estimated_envelope: Envelope,
}

/// One executed sample.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Time (s).
    pub t_s: f64,
    /// Tooth tip (m).
    pub tip_m: [f64; 2],
    /// θ₁, θ₂, θ₃ (rad).
    pub joints_rad: [f64; 3],
    /// Joint rates (rad/s).
    pub joint_rates_rad_s: [f64; 3],
    /// φ = θ₁ + θ₂ + θ₃ (rad).
    pub attitude_rad: f64,
    /// Joint torques from the Lagrange dynamics (N·m).
    pub torques_nm: [f64; 3],
    /// The same as the machine measures them, with the sensor's noise (N·m).
    pub measured_torques_nm: [f64; 3],
    /// Digging resistance on the tooth (soil, plus the boulder at a contact) (N).
    pub digging_force_n: [f64; 2],
    /// Its magnitude (N).
    pub digging_force_magnitude_n: f64,
    /// Soil carried in the bucket (kg).
    pub load_kg: f64,
    /// [HE eq. 2] volume swept so far (soil and any boulder inside it) (m³).
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
    /// Start (s).
    pub t_start_s: f64,
    /// End, or the contact that cut it short (s).
    pub t_end_s: f64,
    /// Planned duration (s).
    pub planned_duration_s: f64,
    /// Start point (m).
    pub from_m: [f64; 2],
    /// Planned end point (m).
    pub to_m: [f64; 2],
    /// Volume planned for it ([HE eq. 2]; none for a detour) (m³).
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
    /// The goal line x (m).
    pub goal_x_m: f64,
    /// The forward search's grid path and its P/Q counts.
    pub search: SearchPath,
    /// The smoothed detour, densely sampled (m).
    pub smoothed_m: Vec<[f64; 2]>,
    /// Least distance of the executed detour from the boulder really met
    /// (simulator), past its first tenth (it starts on the rim), the
    /// contact that may cut it short excluded (m).
    pub clearance_m: f64,
    /// The same from the envelope the planner estimated (m).
    pub planned_clearance_m: f64,
    /// The envelope the planner went round.
    pub estimate: Envelope,
    /// Volume counted when it was planned (swept so far and boulders) (m³).
    pub volume_before_replan_m3: f64,
    /// The re-planned path after the detour, sampled in time (m).
    pub replanned_m: Vec<[f64; 2]>,
}

/// The level-1 plan made before any contact.
#[derive(Debug, Clone, Serialize)]
pub struct Level1Report {
    /// (x_begin, ground) (m).
    pub start_m: [f64; 2],
    /// (x_mid, −h) (m).
    pub mid_m: [f64; 2],
    /// (x_end, ground) (m).
    pub end_m: [f64; 2],
    /// Volume of the first half (m³).
    pub first_half_m3: f64,
    /// Volume of the second half (m³).
    pub second_half_m3: f64,
    /// n of the midpoint.
    pub mid_steps: usize,
    /// n of the end point.
    pub end_steps: usize,
    /// Volume the midpoint's last step changed (m³).
    pub first_step_volume_m3: f64,
    /// Volume the end point's last step changed (m³).
    pub second_step_volume_m3: f64,
    /// Durations of descent and rise (s).
    pub durations_s: [f64; 2],
    /// The planned tip path, sampled in time (m) (for plots and CSV; not
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
    /// The boulders as the planner estimated them, with their touches.
    pub estimates: Vec<BoulderEstimate>,
    /// The radius the planner assumed at a first touch (m).
    pub prior_radius_m: f64,
    /// V (m³).
    pub target_volume_m3: f64,
    /// Dug, soil and boulders (module docs) (m³).
    pub achieved_volume_m3: f64,
    /// Soil alone (m³).
    pub soil_volume_m3: f64,
    /// Boulders counted as dug (m³).
    pub obstacle_volume_m3: f64,
    /// What the planner believes it dug: the same count with its estimated
    /// boulders instead of the real ones (m³).
    pub believed_volume_m3: f64,
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
    /// Length of the dig (s).
    pub duration_s: f64,
    /// Least signed distance of the executed tip from any envelope (0 when
    /// touching at a contact; never negative) (m); none without boulders.
    pub min_envelope_distance_m: Option<f64>,
    /// max over consecutive samples and joints of |Δθ| / (θ̇_max·Δt): at most 1
    /// means no jump beyond the speed limits.
    pub max_joint_step_ratio: f64,
    /// Peak |τ| per joint, the stall at a contact included (N·m).
    pub peak_torques_nm: [f64; 3],
    /// Peak soil resistance (contacts excluded) (N).
    pub peak_soil_force_n: f64,
    /// Wall time of planning and simulation (ms).
    pub plan_time_ms: f64,
}

/// The summary the CLI prints (SPEC §6).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// V (m³).
    pub target_volume_m3: f64,
    /// Dug (m³).
    pub achieved_volume_m3: f64,
    /// (achieved − target)/target.
    pub volume_error: f64,
    /// Soil alone (m³).
    pub soil_volume_m3: f64,
    /// Boulders counted (m³).
    pub obstacle_volume_m3: f64,
    /// See [`Excavation::believed_volume_m3`].
    pub believed_volume_m3: f64,
    /// See [`Excavation::prior_radius_m`].
    pub prior_radius_m: f64,
    /// The boulders as the planner estimated them.
    pub estimates: Vec<BoulderEstimate>,
    /// Contacts.
    pub contacts: Vec<ContactReport>,
    /// First contact's side (`over`, `under`), or none.
    pub avoid_direction: Option<AvoidSide>,
    /// Dig duration (s).
    pub duration_s: f64,
    /// Midpoint and end point of the first plan (m).
    pub level1_mid_m: [f64; 2],
    /// End point of the first plan (m).
    pub level1_end_m: [f64; 2],
    /// Where the dig actually ended (m).
    pub final_tip_m: [f64; 2],
    /// See [`Excavation::min_envelope_distance_m`].
    pub min_envelope_distance_m: Option<f64>,
    /// See [`Excavation::max_joint_step_ratio`].
    pub max_joint_step_ratio: f64,
    /// Peak |τ| per joint, the stall at a contact included (N·m).
    pub peak_torques_nm: [f64; 3],
    /// Peak soil resistance (N).
    pub peak_soil_force_n: f64,
    /// Wall time (ms).
    pub plan_time_ms: f64,
}

impl Sample {
    fn measured_torques(&self) -> Joints {
        Joints::new(
            self.measured_torques_nm[0],
            self.measured_torques_nm[1],
            self.measured_torques_nm[2],
        )
    }
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
            believed_volume_m3: self.believed_volume_m3,
            prior_radius_m: self.prior_radius_m,
            estimates: self.estimates.clone(),
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

    /// The executed tip path (m).
    pub fn executed_path(&self) -> Vec<[f64; 2]> {
        self.samples.iter().map(|s| s.tip_m).collect()
    }

    /// The first (level-1) plan's tip path, before any contact (m).
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

    /// Peak |F| on the tooth over the dig, contacts included (0 without samples) (N).
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
///
/// The scenario is split at once: the planner gets [`Scenario::brief`] (the
/// dig, its settings, the ground) and learns of boulders only through what
/// the machine measures at a contact; the boulders, the soil and the sensor
/// noise stay with the simulator, and the result is measured on them.
pub fn excavate(scenario: &Scenario, profile: &MachineProfile) -> Result<Excavation> {
    let started = Instant::now();
    let machine = Backhoe::new(profile);
    let world = SoilSim {
        machine: &machine,
        ground: &scenario.ground,
        soil: &scenario.soil,
        obstacles: &scenario.obstacles,
        bucket_width_m: profile.bucket.width_m,
        max_force_n: profile.force.max_digging_force_n,
    };
    let planner = Planner::new(scenario.brief(), profile);
    let mut run = Run::new(scenario, profile, world, planner);
    let mut ex = run.execute()?;
    ex.plan_time_ms = started.elapsed().as_secs_f64() * 1e3;
    Ok(ex)
}

/// One pass: the machine in the simulated soil (truth), the planner fed
/// with touches, and the record of what happened.
struct Run<'a> {
    sc: &'a Scenario,
    world: SoilSim<'a>,
    sensor: TorqueSensor,
    planner: Planner<'a>,
    dynamics: Dynamics,
    width_m: f64,
    /// Boulders of the scenario the tooth has met (truth, for the record).
    met: Vec<bool>,
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
    fn new(
        sc: &'a Scenario,
        profile: &MachineProfile,
        world: SoilSim<'a>,
        planner: Planner<'a>,
    ) -> Self {
        Self {
            sc,
            world,
            sensor: TorqueSensor::new(&sc.sensing),
            planner,
            dynamics: Dynamics::new(profile),
            width_m: profile.bucket.width_m,
            met: vec![false; sc.obstacles.len()],
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
        let (plan, first) = self.planner.first_plan()?;
        let mut pending: VecDeque<PlannedSegment> = first.into();
        let planned_s = pending.iter().map(|ps| ps.segment.duration_s()).sum();
        self.check_steps(planned_s, "the level-1 plan")?;
        let level1 = self.level1_report(&plan);

        // The first sample, at rest at the start.
        let machine = self.world.machine;
        let first = plan.first.segment.state(machine, 0.0);
        self.tips.push(first.tip);
        self.push_sample(0.0, &first, Vec2::zeros(), 0, SegmentKind::Descent, false);

        while let Some(ps) = pending.pop_front() {
            let seg_index = self.segments.len();
            let seg = &ps.segment;
            let from = seg.tip(machine, 0.0);
            let to = seg.tip(machine, seg.duration_s());
            let after = self.contacts.len();
            self.check_steps(
                self.t_s + seg.duration_s(),
                &format!("the dig after {after} contact(s)"),
            )?;
            let run = self.world.advance(seg, sc.planner.dt_s);
            let t0 = self.t_s;
            let n = run.states.len();
            for (k, (t, state)) in run.states.iter().enumerate() {
                let is_contact = run.contact.is_some() && k + 1 == n;
                let mut force = self.world.resistance(state);
                let soil_force = force.norm();
                if !is_contact {
                    self.peak_soil_force_n = self.peak_soil_force_n.max(soil_force);
                    if soil_force > self.world.max_force_n {
                        return Err(ExcavateError::SoilTooHard {
                            t_s: t0 + t,
                            force_n: soil_force,
                            max_n: self.world.max_force_n,
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
                        self.planner.descent_completed();
                    }
                }
                Some(c) => {
                    if self.contacts.len() >= sc.planner.max_contacts {
                        return Err(ExcavateError::TooManyContacts {
                            max: sc.planner.max_contacts,
                        });
                    }
                    // What the machine knows of the contact: its joints, tip and
                    // velocity, and the torques it measured there and a step before.
                    let k = self.samples.len();
                    let touch = Touch {
                        q: c.state.q,
                        point: c.point,
                        velocity: c.velocity,
                        torques_nm: self.samples[k - 1].measured_torques(),
                        torques_before_nm: self.samples[k.saturating_sub(2)].measured_torques(),
                    };
                    let reading = self.planner.read_touch(&touch);
                    self.contacts.push(ContactReport {
                        obstacle: c.obstacle,
                        t_s: t_end,
                        point_m: [c.point.x, c.point.y],
                        velocity_m_s: [c.velocity.x, c.velocity.y],
                        force_n: [c.force.x, c.force.y],
                        measured_force_n: reading.force_n,
                        estimated_normal: reading.normal,
                        true_normal: [c.normal.x, c.normal.y],
                        gamma_deg: reading.gamma_rad.to_degrees(),
                        decision: reading.side,
                        estimate: reading.estimate,
                        estimated_envelope: reading.envelope,
                    });
                    self.met[c.obstacle] = true;
                    let (detour, rest) =
                        self.planner
                            .replan(&touch, &reading, &self.tips, self.swept_area)?;
                    self.detours.push(DetourReport {
                        contact: self.contacts.len() - 1,
                        side: reading.side,
                        goal_x_m: detour.goal_x_m,
                        search: detour.search,
                        clearance_m: f64::NAN, // measured on the truth in `finish`
                        planned_clearance_m: detour.planned_clearance_m,
                        estimate: reading.envelope,
                        smoothed_m: detour.smoothed_m,
                        volume_before_replan_m3: detour.volume_before_replan_m3,
                        replanned_m: detour.replanned_m,
                    });
                    pending = rest.into();
                }
            }
        }
        self.finish(level1)
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
        let measured = self.sensor.measure(&tau);
        self.samples.push(Sample {
            t_s,
            tip_m: [state.tip.x, state.tip.y],
            joints_rad: [state.q[0], state.q[1], state.q[2]],
            joint_rates_rad_s: [state.qd[0], state.qd[1], state.qd[2]],
            attitude_rad: state.q.sum(),
            torques_nm: [tau[0], tau[1], tau[2]],
            measured_torques_nm: [measured[0], measured[1], measured[2]],
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
            path_m: self.planner.sample_path(&segs),
        }
    }

    /// Measures the pass on the truth: distances from the real boulders and
    /// the volume with the real boulders.
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
        // Each detour's clearance from the boulder really met: over the
        // samples that executed it (a contact may have cut it short), past
        // their first tenth (it starts on the rim).
        let detour_segments: Vec<usize> = (0..self.segments.len())
            .filter(|&i| self.segments[i].kind == SegmentKind::Detour)
            .collect();
        for (d, &seg) in self.detours.iter_mut().zip(&detour_segments) {
            let real = sc.obstacles[self.contacts[d.contact].obstacle];
            let executed: Vec<&Sample> = self.samples.iter().filter(|s| s.segment == seg).collect();
            let first_tenth = (executed.len() / 10).max(1);
            d.clearance_m = executed
                .iter()
                .skip(first_tenth)
                .filter(|s| !s.contact)
                .map(|s| real.signed_distance(Vec2::new(s.tip_m[0], s.tip_m[1])))
                .fold(f64::INFINITY, f64::min);
        }
        let speed = self.world.machine.limits.speed_rad_s;
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
        let (soil, rock) = counted_volume(
            self.ground(),
            &sc.obstacles,
            &self.met,
            &self.tips,
            self.swept_area,
            self.width_m,
        );
        let prior = self.planner.prior();
        let (believed_soil, believed_rock) = self.planner.counted(&self.tips, self.swept_area);
        Ok(Excavation {
            believed_volume_m3: believed_soil + believed_rock,
            scenario: sc.name.clone(),
            ground: sc.ground.clone(),
            obstacles: sc.obstacles.clone(),
            estimates: self.planner.estimates().boulders().to_vec(),
            prior_radius_m: prior.radius_m,
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
