//! The planner's side of the two-level method (paper §1.2, §2.2): level 1,
//! and after each contact the preimage side, the forward search round the
//! boulder *as estimated*, smoothing and the re-plan of the rest.
//!
//! It is built from a [`Brief`] — the dig, its settings and the ground — and
//! learns of boulders only through [`Touch`]es: what the machine measured at a
//! contact ([`crate::estimate`]). It holds no [`crate::Scenario`] and no
//! simulator, so nothing here can read where a boulder really is, how large
//! it is, or the force the simulator applied; [`crate::excavation`] runs it against
//! the simulator and measures the result on the truth.

use autoshovel_core::Vec2;
use serde::Serialize;

use crate::error::{ExcavateError, Result};
use crate::estimate::{force_from_torques, normal_from_force, BoulderPrior, Estimates, Touch};
use crate::ground::Ground;
use crate::kinematics::{Backhoe, Joints};
use crate::level1::{plan_level1, EndLevel, Level1Plan, StepFound, StepSearch};
use crate::obstacle::Envelope;
use crate::preimage::{decide, AvoidSide};
use crate::profile::MachineProfile;
use crate::scenario::Brief;
use crate::search::{forward_search, SearchParams, SearchPath};
use crate::segment::{Motion, Segment, SegmentKind};
use crate::smooth::smooth_detour;
use crate::volume::{counted_volume, swept_area};

/// How many grid steps past the boulder a detour may be extended to let the
/// re-plan clear it.
const MAX_DETOUR_EXTENSION: usize = 12;

/// Largest radius an estimate may take, in prior radii (a bad fit from two
/// touches cannot make the search grid explode).
const MAX_ESTIMATE_PRIORS: f64 = 3.0;

/// A segment with what its planning said about it.
#[derive(Debug, Clone)]
pub(crate) struct PlannedSegment {
    pub segment: Segment,
    pub volume_m3: Option<f64>,
    pub steps: Option<usize>,
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

/// What the planner made of one touch.
#[derive(Debug, Clone, Serialize)]
pub struct TouchReading {
    /// F̂, the force estimated from the torque jump (N).
    pub force_n: [f64; 2],
    /// n̂, the rock's normal estimated from F̂ (m).
    pub normal: [f64; 2],
    /// γ from V_c to F̂ (see [`crate::preimage`]) (rad).
    pub gamma_rad: f64,
    /// The preimage rule's choice.
    pub side: AvoidSide,
    /// Index of the boulder estimate the touch refined or started.
    pub estimate: usize,
    /// That estimate's envelope after the touch.
    pub envelope: Envelope,
}

/// A detour as planned (the run adds what happened).
#[derive(Debug, Clone)]
pub(crate) struct DetourPlan {
    pub goal_x_m: f64,
    pub search: SearchPath,
    pub smoothed_m: Vec<[f64; 2]>,
    /// Least distance of the detour from the estimated envelope, past its first tenth (m).
    pub planned_clearance_m: f64,
    pub volume_before_replan_m3: f64,
    pub replanned_m: Vec<[f64; 2]>,
}

/// The planner.
pub(crate) struct Planner<'a> {
    brief: Brief<'a>,
    machine: Backhoe,
    width_m: f64,
    attitude: [f64; 3],
    first_half_done: bool,
    prior: BoulderPrior,
    estimates: Estimates,
}

impl<'a> Planner<'a> {
    pub fn new(brief: Brief<'a>, profile: &MachineProfile) -> Self {
        let b = &profile.bucket;
        let p = brief.planner;
        let mut prior = BoulderPrior::from_bucket(b.capacity_m3, b.width_m, p.rock_friction_prior);
        if let Some(r) = p.boulder_radius_m {
            prior.radius_m = r;
        }
        Self {
            brief,
            machine: Backhoe::new(profile),
            width_m: b.width_m,
            attitude: brief.level1_request().attitude_rad,
            first_half_done: false,
            prior,
            estimates: Estimates::default(),
        }
    }

    pub fn prior(&self) -> BoulderPrior {
        self.prior
    }

    pub fn estimates(&self) -> &Estimates {
        &self.estimates
    }

    fn ground(&self) -> &'a Ground {
        self.brief.ground
    }

    fn step_search<'b>(&'b self, known: &'b [Envelope]) -> StepSearch<'b> {
        self.brief.step_search(&self.machine, self.width_m, known)
    }

    /// The tip path of `segments` sampled every dt (m).
    pub fn sample_path(&self, segments: &[Segment]) -> Vec<[f64; 2]> {
        let dt = self.brief.planner.dt_s;
        let mut out = Vec::new();
        for seg in segments {
            let n = (seg.duration_s() / dt).ceil().max(1.0) as usize;
            let tips = seg.sample_tips(&self.machine, n);
            let skip = usize::from(!out.is_empty());
            out.extend(tips.into_iter().skip(skip).map(|p| [p.x, p.y]));
        }
        out
    }

    /// Level 1: the dig before any contact.
    pub fn first_plan(&self) -> Result<(Level1Plan, Vec<PlannedSegment>)> {
        let plan = plan_level1(&self.step_search(&[]), &self.brief.level1_request())?;
        let segments = [plan.first.clone(), plan.second.clone()]
            .into_iter()
            .map(PlannedSegment::from_found)
            .collect();
        Ok((plan, segments))
    }

    /// The descent ran to its end: the first half is done.
    pub fn descent_completed(&mut self) {
        self.first_half_done = true;
    }

    /// (soil, boulders) volume (m³) the planner counts for a path with
    /// [HE eq. 2] area `area`, with its estimated boulders.
    pub fn counted(&self, path: &[Vec2], area: f64) -> (f64, f64) {
        let envelopes = self.estimates.envelopes();
        let met = vec![true; envelopes.len()];
        counted_volume(self.ground(), &envelopes, &met, path, area, self.width_m)
    }

    /// Reads a touch: the force and normal, the estimate it refines or
    /// starts, γ and the side.
    pub fn read_touch(&mut self, touch: &Touch) -> TouchReading {
        let force = force_from_torques(&self.machine, touch);
        let normal = normal_from_force(force, touch.velocity, self.prior.rock_friction);
        let gamma = self
            .brief
            .planner
            .gamma_reading
            .gamma_rad(touch.velocity, force);
        let side = decide(gamma);
        let reach = self.prior.radius_m + 2.0 * self.brief.planner.clearance_m;
        let estimate = self.estimates.add(
            touch.point,
            normal,
            &self.prior,
            reach,
            MAX_ESTIMATE_PRIORS * self.prior.radius_m,
        );
        TouchReading {
            force_n: [force.x, force.y],
            normal: [normal.x, normal.y],
            gamma_rad: gamma,
            side,
            estimate,
            envelope: self.estimates.get(estimate).envelope,
        }
    }

    /// Detour round the estimated boulder of `reading` and re-plan the rest,
    /// from the executed path `tips` (encoders) whose [HE eq. 2] area is
    /// `swept_area`.
    pub fn replan(
        &mut self,
        touch: &Touch,
        reading: &TouchReading,
        tips: &[Vec2],
        swept_area_m2: f64,
    ) -> Result<(DetourPlan, Vec<PlannedSegment>)> {
        let brief = self.brief;
        let met = reading.envelope;
        let known = self.estimates.envelopes();
        let side = reading.side;
        let attitude = touch.q.sum();
        let params = SearchParams {
            step_m: brief.dig.step_m,
            clearance_m: brief.planner.clearance_m,
            window_m: brief.planner.search_window_m,
        };
        let big_r = met.radius_m + params.clearance_m;
        let normal = Vec2::new(reading.normal[0], reading.normal[1]);
        let impassable = |why: String| ExcavateError::ObstacleImpassable {
            index: reading.estimate,
            side,
            contact_m: [touch.point.x, touch.point.y],
            why,
        };
        let mut first_err: Option<ExcavateError> = None;
        for extra in 1..=MAX_DETOUR_EXTENSION {
            let goal_x = met.center().x - big_r - extra as f64 * params.step_m;
            let path = forward_search(
                &self.machine,
                attitude,
                touch.point,
                normal,
                &met,
                side,
                &known,
                goal_x,
                &params,
            )
            .map_err(|f| impassable(f.why))?;
            let detour = smooth_detour(
                &self.machine,
                touch.point,
                &path.waypoints,
                attitude,
                &known,
                brief.planner.speed_fraction,
                brief.planner.min_segment_time_s,
            )
            .map_err(impassable)?;
            let seg = Segment {
                kind: SegmentKind::Detour,
                motion: Motion::Detour(detour),
            };
            // Volume so far: executed path plus the detour.
            let det_tips = seg.sample_tips(&self.machine, brief.planner.trapezoids);
            let mut path_so_far = tips.to_vec();
            path_so_far.extend(det_tips.iter().skip(1));
            let area = swept_area_m2 + swept_area(self.ground(), &det_tips); // [HE eq. 2]
            let (soil, rock) = self.counted(&path_so_far, area);
            let current = soil + rock;
            let end = *det_tips.last().expect("samples");
            let end_q = seg.end_joints(&self.machine);
            match self.plan_rest(end, &end_q, current, &known) {
                Ok(rest) => {
                    let first_tenth = det_tips.len() / 10;
                    let planned_clearance_m = det_tips
                        .iter()
                        .skip(first_tenth.max(1))
                        .map(|p| met.signed_distance(*p))
                        .fold(f64::INFINITY, f64::min);
                    let smoothed_m = match &seg.motion {
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
                    let plan = DetourPlan {
                        goal_x_m: goal_x,
                        search: path,
                        smoothed_m,
                        planned_clearance_m,
                        volume_before_replan_m3: current,
                        replanned_m: self.sample_path(&rest_segments),
                    };
                    let mut out = vec![PlannedSegment {
                        segment: seg,
                        volume_m3: None,
                        steps: None,
                    }];
                    out.extend(rest);
                    return Ok((plan, out));
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

    /// Level 1 from a detour's end to the remaining volume (module docs of
    /// [`crate::excavation`]).
    fn plan_rest(
        &mut self,
        from: Vec2,
        from_q: &Joints,
        current_m3: f64,
        known: &[Envelope],
    ) -> Result<Vec<PlannedSegment>> {
        let d = self.brief.dig;
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
}
