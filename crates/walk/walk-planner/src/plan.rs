//! Whole travel plans: checks a scenario's poses, runs the potential-field
//! descent leg by leg (a V-shape is a reverse leg to the midpoint and a
//! forward leg on to the goal), smooths each leg, checks the smoothed path's
//! clearance and measures the result (SPEC §2 outputs).

use std::time::Instant;

use autoshovel_core::{angle_diff, heading_vec, Pose2, Vec2};
use serde::Serialize;

use crate::apf::{descend, ApfParams, FieldKind, Target};
use crate::error::{PoseFault, PropelError, Result};
use crate::map::Map;
use crate::path::{Direction, Leg, Path, PathPoint};
use crate::scenario::Scenario;
use crate::smooth::{smooth, SmoothParams};

/// Options of one plan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlanOptions {
    /// Classic or improved field.
    pub field: FieldKind,
    /// Field and descent parameters.
    pub apf: ApfParams,
    /// Smoothing parameters.
    pub smooth: SmoothParams,
}

impl PlanOptions {
    /// The defaults of a field kind.
    pub fn new(field: FieldKind) -> Self {
        let apf = match field {
            FieldKind::Classic => ApfParams::classic(),
            FieldKind::Improved => ApfParams::improved(),
        };
        Self {
            field,
            apf,
            smooth: SmoothParams::default(),
        }
    }
}

/// What happened on one leg.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LegStats {
    /// Forward or reverse.
    pub direction: Direction,
    /// Descent steps.
    pub iterations: usize,
    /// Local-minimum escapes used (boundary following).
    pub escapes: usize,
    /// Control-point spacing the smoothing finally used (m).
    pub control_spacing_m: f64,
    /// Length of the raw descent polyline (m).
    pub raw_length_m: f64,
    /// Length of the smoothed leg (m).
    pub length_m: f64,
    /// Heading error at the end of the leg (deg).
    pub end_heading_error_deg: f64,
}

/// Measures of a whole plan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanMetrics {
    /// Total smoothed length (m).
    pub length_m: f64,
    /// Smallest footprint clearance along the smoothed path (m).
    pub min_clearance_m: f64,
    /// Where that is.
    pub min_clearance_at: [f64; 2],
    /// Heading error on arrival at the goal (deg).
    pub final_heading_error_deg: f64,
    /// Heading error when leaving the start (deg).
    pub start_heading_error_deg: f64,
    /// Largest heading mismatch at a cusp between legs (V-shape midpoint) (deg).
    pub cusp_heading_error_deg: f64,
    /// Largest |curvature| (1/m).
    pub max_curvature_per_m: f64,
    /// Mean |curvature| over the samples (1/m).
    pub mean_abs_curvature_per_m: f64,
    /// Escapes used on all legs.
    pub escapes: usize,
    /// Descent steps on all legs.
    pub iterations: usize,
    /// Wall-clock planning time (ms).
    pub plan_time_ms: f64,
}

/// A finished plan.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The path.
    pub path: Path,
    /// Per-leg statistics.
    pub legs: Vec<LegStats>,
    /// Measures.
    pub metrics: PlanMetrics,
}

/// The goal-approach check distance: the machine arrives along the required
/// heading, so this much of the ray behind the goal must be free (m).
const APPROACH_CHECK_M: f64 = 1.0;

/// Checks that the machine can stand at `pose` and leave or arrive along its
/// motion heading.
fn check_pose(
    map: &Map,
    r_fp: f64,
    which: &'static str,
    pose: Pose2,
    motion_heading: f64,
    arriving: bool,
) -> Result<()> {
    let bad = |fault: PoseFault| PropelError::BadPose {
        which,
        x: pose.x,
        y: pose.y,
        fault,
    };
    if !pose.is_finite() {
        return Err(bad(PoseFault::NotFinite {
            heading_rad: pose.theta,
        }));
    }
    let p = pose.position();
    if !map.contains(p) {
        return Err(bad(PoseFault::OutsideSite {
            min_m: [map.min.x, map.min.y],
            max_m: [map.max.x, map.max.y],
        }));
    }
    let nb = map.nearest(p);
    let c = nb.distance - r_fp;
    if c <= 0.0 {
        return Err(bad(PoseFault::TooClose {
            element: map.element_name(nb.element).to_string(),
            clearance_m: c,
            footprint_radius_m: r_fp,
        }));
    }
    // The stretch the machine must travel straight along its heading.
    let h = heading_vec(motion_heading) * if arriving { -1.0 } else { 1.0 };
    for i in 1..=10 {
        let q = p + h * (APPROACH_CHECK_M * i as f64 / 10.0);
        let nb = map.nearest(q);
        if nb.distance - r_fp <= 0.0 {
            return Err(bad(PoseFault::HeadingBlocked {
                heading_deg: pose.theta.to_degrees(),
                element: map.element_name(nb.element).to_string(),
                within_m: APPROACH_CHECK_M,
                arriving,
            }));
        }
    }
    Ok(())
}

/// Plans the scenario's path with the given options.
///
/// Errors: a pose the machine cannot take ([`PropelError::BadPose`]), a local
/// minimum the descent could not leave ([`PropelError::LocalMinimum`]), or a
/// raw or smoothed path that comes too close to an obstacle
/// ([`PropelError::Collision`]).
pub fn plan_path(scenario: &Scenario, opts: &PlanOptions) -> Result<Plan> {
    let t0 = Instant::now();
    let map = &scenario.map;
    let r_fp = scenario.footprint_radius_m;
    opts.apf
        .validate()
        .map_err(|(name, value)| PropelError::BadOption { name, value })?;
    let legs_spec = scenario.legs();
    for (i, (from, to, dir)) in legs_spec.iter().enumerate() {
        let which_from = if i == 0 { "start" } else { "midpoint" };
        let which_to = if i + 1 == legs_spec.len() {
            "goal"
        } else {
            "midpoint"
        };
        check_pose(
            map,
            r_fp,
            which_from,
            *from,
            dir.motion_heading(from.theta),
            false,
        )?;
        check_pose(map, r_fp, which_to, *to, dir.motion_heading(to.theta), true)?;
    }

    let mut legs = Vec::new();
    let mut stats = Vec::new();
    let mut s_offset = 0.0;
    let mut total_iter = 0;
    let mut total_esc = 0;
    for (i, (from, to, dir)) in legs_spec.iter().enumerate() {
        if (to.position() - from.position()).norm() <= opts.apf.goal_tolerance_m {
            // Already there: a leg of one pose (its heading error says whether it is enough).
            let point = PathPoint {
                pose: *from,
                s_m: s_offset,
                curvature_per_m: 0.0,
            };
            let leg = Leg {
                direction: *dir,
                raw: vec![from.position()],
                points: vec![point],
            };
            stats.push(LegStats {
                direction: *dir,
                iterations: 0,
                escapes: 0,
                control_spacing_m: 0.0,
                raw_length_m: 0.0,
                length_m: 0.0,
                end_heading_error_deg: angle_diff(from.theta, to.theta).abs().to_degrees(),
            });
            legs.push(leg);
            continue;
        }
        let target = Target {
            position: to.position(),
            motion_heading_rad: dir.motion_heading(to.theta),
        };
        let d = descend(
            map,
            from.position(),
            dir.motion_heading(from.theta),
            &target,
            r_fp,
            opts.field,
            &opts.apf,
        );
        total_iter += d.iterations;
        total_esc += d.escapes;
        if let Some(q) = d.stalled_at {
            return Err(PropelError::LocalMinimum {
                x: q.x,
                y: q.y,
                leg: i,
                iterations: d.iterations,
                distance_to_goal_m: (target.position - q).norm(),
                escapes: d.escapes,
            });
        }
        for q in &d.raw {
            let nb = map.nearest(*q);
            if nb.distance - r_fp <= 0.0 {
                return Err(PropelError::Collision {
                    stage: "raw",
                    leg: i,
                    x: q.x,
                    y: q.y,
                    clearance_m: nb.distance - r_fp,
                    obstacle: map.element_name(nb.element).to_string(),
                });
            }
        }
        let keep = if opts.apf.lead_in_m > 0.0 {
            ((opts.apf.lead_in_m / opts.apf.step_m).ceil() as usize).min(d.raw.len() - 1)
        } else {
            0
        };
        let mut spacing = opts.smooth.control_spacing_m;
        let samples = loop {
            let samples = smooth(&d.raw, spacing, opts.smooth.sample_spacing_m, keep);
            let worst = samples
                .iter()
                .map(|c| (c, map.nearest(c.point)))
                .min_by(|a, b| a.1.distance.total_cmp(&b.1.distance));
            match worst {
                Some((c, nb)) if nb.distance - r_fp <= 0.0 => {
                    if spacing * 0.5 < opts.smooth.min_control_spacing_m {
                        return Err(PropelError::Collision {
                            stage: "smoothed",
                            leg: i,
                            x: c.point.x,
                            y: c.point.y,
                            clearance_m: nb.distance - r_fp,
                            obstacle: map.element_name(nb.element).to_string(),
                        });
                    }
                    spacing *= 0.5;
                }
                _ => break samples,
            }
        };
        let flip = if *dir == Direction::Reverse {
            std::f64::consts::PI
        } else {
            0.0
        };
        let mut last_tangent = heading_vec(dir.motion_heading(from.theta));
        let points: Vec<PathPoint> = samples
            .iter()
            .map(|c| {
                if c.tangent.norm() > 0.5 {
                    last_tangent = c.tangent;
                }
                let theta =
                    autoshovel_core::wrap_angle(last_tangent.y.atan2(last_tangent.x) + flip);
                PathPoint {
                    pose: Pose2::new(c.point.x, c.point.y, theta),
                    s_m: s_offset + c.s,
                    curvature_per_m: c.curvature,
                }
            })
            .collect();
        let leg = Leg {
            direction: *dir,
            raw: d.raw.clone(),
            points,
        };
        s_offset += leg.length_m();
        let end_err = leg
            .points
            .last()
            .map(|p| angle_diff(p.pose.theta, to.theta).abs().to_degrees())
            .unwrap_or(f64::NAN);
        stats.push(LegStats {
            direction: *dir,
            iterations: d.iterations,
            escapes: d.escapes,
            control_spacing_m: spacing,
            raw_length_m: autoshovel_core::polyline_length(&d.raw),
            length_m: leg.length_m(),
            end_heading_error_deg: end_err,
        });
        legs.push(leg);
    }
    let path = Path { legs };
    let mut metrics = measure(&path, scenario);
    metrics.escapes = total_esc;
    metrics.iterations = total_iter;
    metrics.plan_time_ms = t0.elapsed().as_secs_f64() * 1e3;
    Ok(Plan {
        path,
        legs: stats,
        metrics,
    })
}

/// Measures a path against its scenario: length, clearance, heading errors, curvature.
pub fn measure(path: &Path, scenario: &Scenario) -> PlanMetrics {
    let map = &scenario.map;
    let mut min_c = f64::INFINITY;
    let mut min_at = [f64::NAN; 2];
    let mut max_k: f64 = 0.0;
    let mut sum_k = 0.0;
    let mut n = 0usize;
    for (_, p) in path.samples() {
        let c = map.clearance(p.pose.position(), scenario.footprint_radius_m);
        if c < min_c {
            min_c = c;
            min_at = [p.pose.x, p.pose.y];
        }
        max_k = max_k.max(p.curvature_per_m.abs());
        sum_k += p.curvature_per_m.abs();
        n += 1;
    }
    let final_err = path
        .end_pose()
        .map(|e| angle_diff(e.theta, scenario.goal.theta).abs().to_degrees())
        .unwrap_or(f64::NAN);
    let start_err = path
        .legs
        .first()
        .and_then(|l| l.points.first())
        .map(|p| {
            angle_diff(p.pose.theta, scenario.start.theta)
                .abs()
                .to_degrees()
        })
        .unwrap_or(f64::NAN);
    let mut cusp: f64 = 0.0;
    for w in path.legs.windows(2) {
        if let (Some(a), Some(b)) = (w[0].points.last(), w[1].points.first()) {
            cusp = cusp.max(angle_diff(a.pose.theta, b.pose.theta).abs().to_degrees());
        }
    }
    PlanMetrics {
        length_m: path.length_m(),
        min_clearance_m: min_c,
        min_clearance_at: min_at,
        final_heading_error_deg: final_err,
        start_heading_error_deg: start_err,
        cusp_heading_error_deg: cusp,
        max_curvature_per_m: max_k,
        mean_abs_curvature_per_m: if n > 0 { sum_k / n as f64 } else { 0.0 },
        escapes: 0,
        iterations: 0,
        plan_time_ms: 0.0,
    }
}

/// The straight-line points of a path's samples (for plots and A* comparison).
pub fn sample_points(path: &Path) -> Vec<Vec2> {
    path.samples().map(|(_, p)| p.pose.position()).collect()
}
