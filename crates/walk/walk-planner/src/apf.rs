//! Artificial potential field descent: the classic field (electric-shovel
//! walking paper [W eqs. 1–5]) and the improved field ([W eqs. 6–15]), with stall detection
//! and a boundary-following escape.
//!
//! How the printed equations were read (SPEC §2 asks for the physics the text
//! describes):
//! - ρ(q, q_o) is the clearance of the machine's footprint disc to the
//!   obstacle's *nearest point*, so the field is infinite on contact; ∇ρ(q, q_o)
//!   is the unit vector from that point to the machine. [W eq. 4] prints
//!   ρ(q, q_t) where ρ(q, q_o) is meant.
//! - [W eq. 8] caps the attraction beyond ρ_d at ½ηρ_d, half of what it is just
//!   inside ρ_d: the printed potential's slope jumps there. We use the C¹
//!   capped field (|F| = ηρ_d beyond ρ_d), which is what "capped attraction"
//!   describes and keeps the descent from kinking at ρ_d.
//! - [W eqs. 9–11] scale the repulsion by ρⁿ(q, q_t). We measure that distance in
//!   units of ρ_d and saturate it at 1, min(ρ(q, q_t)/ρ_d, 1)ⁿ, so that k keeps
//!   the units of the classic field and far from the target the repulsion is
//!   the classic one. Unbounded, ρⁿ grows with the distance to the target and
//!   walls off every gap between an obstacle and the road edge (the random
//!   road study failed on most maps that way). F_rep1 pushes from the obstacle to the machine and F_rep2, the
//!   derivative of the same potential with respect to ρ(q, q_t), pulls the
//!   machine towards the target ([W eq. 11]: F_rep2 = n/2·k(1/ρ − 1/ρ0)²ρⁿ⁻¹).
//!   Both vanish at the target, so a goal next to an obstacle is reachable.
//! - [W eqs. 12–13]: the virtual obstacle at the target pushes with magnitude
//!   μ·min(ρ(q, q_t), ρ_t) *against the required final heading h*. With the
//!   attraction −ηρ u (u from target to machine) the motion direction is
//!   −(ηu + μh): the ray behind the target (u = −h) is the only stable
//!   approach, and the angle off it shrinks like ρ^{μ/(η−μ)}, so the machine
//!   arrives aligned. This needs μ < η. [W eq. 13]'s cap ½μρ_d is read as the
//!   same C¹ cap as the attraction, μρ_t.
//!
//! - The planner never evaluates a potential: [W eq. 7] (the gradient that
//!   turns [W eq. 6] into the force of [W eq. 8]) is done on paper, and the
//!   total potential [W eq. 14] is descended through its force, [W eq. 15].
//!
//! Descent: q ← q + δ·F/|F| with a fixed step δ, stopping within the goal
//! tolerance. A stall is no net progress: over the last `stall_window` steps
//! the machine moved less than `stall_ratio` of the distance it stepped
//! (oscillation or standstill). On a stall the improved planner may escape by
//! following the nearest obstacle's boundary (a tangent-bug move) until it is
//! closer to the target than where it stalled and the field points onwards;
//! every escape is counted and reported.

use autoshovel_core::{heading_vec, perp, Vec2};
use serde::{Deserialize, Serialize};

use crate::map::Map;

/// Which field to descend.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FieldKind {
    /// [W eqs. 1–5]: quadratic attraction, Khatib repulsion; no heading control.
    Classic,
    /// [W eqs. 6–15]: capped attraction, ρⁿ-scaled repulsion, virtual obstacle at the target.
    Improved,
}

impl FieldKind {
    /// CLI name: `apf` or `improved-apf`.
    pub fn name(self) -> &'static str {
        match self {
            FieldKind::Classic => "apf",
            FieldKind::Improved => "improved-apf",
        }
    }
}

/// Parameters of the potential field and of the descent.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ApfParams {
    /// Attraction gain η ([W eq. 1]) (1/m, force per metre).
    pub eta: f64,
    /// Attraction cap distance ρ_d ([W eq. 6]) (m); improved field only.
    pub rho_d_m: f64,
    /// Repulsion gain k ([W eqs. 3, 9]).
    pub k_rep: f64,
    /// Repulsion influence range ρ0 ([W eq. 3]) (m).
    pub rho0_m: f64,
    /// Exponent n of ρⁿ(q, q_t) ([W eq. 9]); improved field only.
    pub n: f64,
    /// Virtual-obstacle gain μ ([W eq. 12]), below η; improved field only.
    pub mu: f64,
    /// Virtual-obstacle cap distance ρ_t ([W eq. 12]) (m).
    pub rho_t_m: f64,
    /// Descent step δ (m).
    pub step_m: f64,
    /// The leg ends within this distance of the target (m).
    pub goal_tolerance_m: f64,
    /// Straight run along the start heading before the field takes over (m)
    /// (a crawler leaves the way it faces; 0 disables).
    pub lead_in_m: f64,
    /// Floor of the clearance in the repulsion, against division by zero (m).
    pub min_clearance_m: f64,
    /// Steps over which progress is judged.
    pub stall_window: usize,
    /// Stall when the net displacement over the window is below this share of the distance stepped.
    pub stall_ratio: f64,
    /// Escape local minima by boundary following (else report them as errors).
    pub escape: bool,
    /// Escapes allowed per leg before giving up.
    pub max_escapes: usize,
    /// Give up after this many steps per metre of straight-line distance (plus 2000).
    pub steps_per_m_limit: f64,
}

impl Default for ApfParams {
    fn default() -> Self {
        Self::improved()
    }
}

impl ApfParams {
    /// Defaults of the improved field, tuned on the random haul-road study
    /// (docs/propel-study.md) for the 1:7 prototype's scale (SPEC §3).
    pub fn improved() -> Self {
        Self {
            eta: 1.0,
            rho_d_m: 10.0,
            k_rep: 0.7,
            rho0_m: 2.0,
            n: 2.0,
            mu: 0.85,
            rho_t_m: 5.0,
            step_m: 0.1,
            goal_tolerance_m: 0.15,
            lead_in_m: 1.0,
            min_clearance_m: 0.01,
            stall_window: 40,
            stall_ratio: 0.1,
            escape: true,
            max_escapes: 8,
            steps_per_m_limit: 40.0,
        }
    }

    /// The classic baseline: the same gains, no escape (it is the baseline's
    /// failure that the improved field answers).
    pub fn classic() -> Self {
        Self {
            escape: false,
            ..Self::improved()
        }
    }

    /// Checks ranges; returns the name and value of the first bad parameter.
    pub fn validate(&self) -> Result<(), (&'static str, f64)> {
        let positive = [
            ("eta", self.eta),
            ("rho_d_m", self.rho_d_m),
            ("k_rep", self.k_rep),
            ("rho0_m", self.rho0_m),
            ("rho_t_m", self.rho_t_m),
            ("step_m", self.step_m),
            ("goal_tolerance_m", self.goal_tolerance_m),
            ("min_clearance_m", self.min_clearance_m),
            ("stall_ratio", self.stall_ratio),
            ("steps_per_m_limit", self.steps_per_m_limit),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err((name, v));
            }
        }
        for (name, v) in [
            ("n", self.n),
            ("mu", self.mu),
            ("lead_in_m", self.lead_in_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((name, v));
            }
        }
        if self.mu >= self.eta {
            return Err(("mu (must be below eta)", self.mu));
        }
        if self.stall_window < 2 {
            return Err(("stall_window", self.stall_window as f64));
        }
        Ok(())
    }
}

/// The target of one descent.
#[derive(Debug, Clone, Copy)]
pub struct Target {
    /// Goal position (m).
    pub position: Vec2,
    /// Required heading of *motion* on arrival (rad).
    pub motion_heading_rad: f64,
}

/// The total force of the field at `q`: the classic field [W eq. 5]
/// (attraction [W eq. 2] plus Khatib repulsion [W eq. 4]) or the improved
/// field [W eq. 15] (capped attraction [W eq. 8], virtual obstacle at the
/// target [W eq. 13], ρⁿ-scaled repulsion [W eq. 10] with its parts
/// [W eq. 11] and factor [W eq. 9]); see the module notes for how each was read.
pub fn field_force(
    map: &Map,
    q: Vec2,
    target: &Target,
    footprint_radius_m: f64,
    kind: FieldKind,
    p: &ApfParams,
) -> Vec2 {
    let d = target.position - q;
    let rt = d.norm();
    let u_goal = if rt > 1e-12 { d / rt } else { Vec2::zeros() };
    let mut f = match kind {
        // [W eq. 2]: F_att = ηρ(q, q_t) towards the target.
        FieldKind::Classic => d * p.eta,
        FieldKind::Improved => {
            // [W eq. 8]: attraction capped beyond ρ_d (C¹ reading).
            let att = if rt <= p.rho_d_m {
                d * p.eta
            } else {
                u_goal * (p.eta * p.rho_d_m)
            };
            // [W eq. 13]: the virtual obstacle pushes against the required heading.
            let virt = -heading_vec(target.motion_heading_rad) * (p.mu * rt.min(p.rho_t_m));
            att + virt
        }
    };
    // (ρ(q,q_t)/ρ_d)ⁿ, saturating at 1 beyond ρ_d (see the module notes).
    let s = (rt / p.rho_d_m).min(1.0); // [W eq. 9]: the ρⁿ(q, q_t) factor
    let far = rt > p.rho_d_m;
    map.for_each_nearest(q, |nb| {
        let rho = (nb.distance - footprint_radius_m).max(p.min_clearance_m);
        if rho >= p.rho0_m {
            return;
        }
        let a = 1.0 / rho - 1.0 / p.rho0_m;
        match kind {
            // [W eq. 4]: F_rep = k(1/ρ − 1/ρ0)/ρ² along ∇ρ(q, q_o).
            FieldKind::Classic => f += nb.normal * (p.k_rep * a / (rho * rho)),
            FieldKind::Improved => {
                // [W eq. 11]: F*_rep1 and F*_rep2.
                let rep1 = p.k_rep * a * s.powf(p.n) / (rho * rho);
                let rep2 = if far {
                    0.0
                } else {
                    0.5 * p.n * p.k_rep * a * a * s.powf(p.n - 1.0) / p.rho_d_m
                };
                f += nb.normal * rep1 + u_goal * rep2; // [W eq. 10]
            }
        }
    });
    f // [W eq. 5] (classic) / [W eq. 15] (improved): the sum of the forces
}

/// Outcome of one descent.
#[derive(Debug, Clone)]
pub struct Descent {
    /// The polyline from the start to the target (ends exactly at the target on success).
    pub raw: Vec<Vec2>,
    /// Steps taken.
    pub iterations: usize,
    /// Escapes used.
    pub escapes: usize,
    /// Where the descent stalled and gave up, if it did.
    pub stalled_at: Option<Vec2>,
}

/// Descends the field from `start` (leaving along `start_motion_heading_rad`)
/// to the target. Never loops forever: gives up after the step limit or
/// `max_escapes` stalls, returning the partial path with `stalled_at` set.
pub fn descend(
    map: &Map,
    start: Vec2,
    start_motion_heading_rad: f64,
    target: &Target,
    footprint_radius_m: f64,
    kind: FieldKind,
    p: &ApfParams,
) -> Descent {
    let mut raw = vec![start];
    if p.lead_in_m > 0.0 {
        let h = heading_vec(start_motion_heading_rad);
        let n = (p.lead_in_m / p.step_m).ceil().max(1.0) as usize;
        for i in 1..=n {
            let q = start + h * (p.lead_in_m * i as f64 / n as f64);
            if map.clearance(q, footprint_radius_m) <= 0.0
                || (q - target.position).norm() <= p.goal_tolerance_m
            {
                break;
            }
            raw.push(q);
        }
    }
    let dist0 = (target.position - start).norm();
    let max_steps = (dist0 * p.steps_per_m_limit) as usize + 2000;
    let mut iterations = 0;
    let mut escapes = 0;
    let mut resume_index = raw.len() - 1;
    let mut stalls: Vec<Vec2> = Vec::new();
    loop {
        let q = *raw.last().expect("raw starts non-empty");
        if (target.position - q).norm() <= p.goal_tolerance_m {
            if (target.position - q).norm() > 0.0 {
                raw.push(target.position);
            }
            return Descent {
                raw,
                iterations,
                escapes,
                stalled_at: None,
            };
        }
        let f = field_force(map, q, target, footprint_radius_m, kind, p);
        let fnorm = f.norm();
        let mut stalled = iterations >= max_steps || !fnorm.is_finite() || fnorm < 1e-12;
        if !stalled {
            let next = q + f * (p.step_m / fnorm);
            if map.clearance(next, footprint_radius_m) <= 0.0 {
                stalled = true;
            } else {
                raw.push(next);
                iterations += 1;
                let since = raw.len() - 1 - resume_index;
                if since >= p.stall_window {
                    let back = raw[raw.len() - 1 - p.stall_window];
                    if (next - back).norm() < p.stall_ratio * p.stall_window as f64 * p.step_m {
                        stalled = true;
                    }
                }
            }
        }
        if !stalled {
            continue;
        }
        // Drop the hesitation: back to where the stall window began.
        if raw.len() > resume_index + p.stall_window {
            raw.truncate(raw.len() - p.stall_window);
        }
        let q = *raw.last().expect("non-empty");
        if !p.escape || escapes >= p.max_escapes || iterations >= max_steps {
            return Descent {
                raw,
                iterations,
                escapes,
                stalled_at: Some(q),
            };
        }
        escapes += 1;
        // Stalling again where it stalled before: the field leads back into the
        // same basin, so follow the boundary further before leaving it.
        let repeats = stalls.iter().filter(|s| (*s - q).norm() < 2.0).count() as i32;
        stalls.push(q);
        let margin = 2.0 * p.step_m * 4f64.powi(repeats);
        // Try both ways round, first at half the influence range (or the
        // clearance held at the stall, if more), then closer (a narrow gap closes the level set of a wide clearance);
        // keep the shorter way that gets past.
        let budget_left = max_steps.saturating_sub(iterations);
        let mut keep = (map.nearest(q).distance - footprint_radius_m)
            .max(0.5 * p.rho0_m)
            .min(p.rho0_m);
        let best = loop {
            // The second side only needs to beat the first one's length.
            let first = follow_boundary(
                map,
                q,
                target,
                footprint_radius_m,
                kind,
                p,
                1.0,
                keep,
                margin,
                budget_left,
            );
            let limit = first
                .as_ref()
                .map_or(budget_left, |seg| seg.len().saturating_sub(1));
            let second = follow_boundary(
                map,
                q,
                target,
                footprint_radius_m,
                kind,
                p,
                -1.0,
                keep,
                margin,
                limit,
            );
            let found = second.or(first);
            if found.is_some() || keep < 2.0 * MIN_FOLLOW_CLEARANCE_M {
                break found;
            }
            keep = (keep * 0.5).max(MIN_FOLLOW_CLEARANCE_M);
        };
        match best {
            Some(seg) => {
                iterations += seg.len();
                raw.extend(seg);
                resume_index = raw.len() - 1;
            }
            None => {
                return Descent {
                    raw,
                    iterations,
                    escapes,
                    stalled_at: Some(q),
                }
            }
        }
    }
}

/// Name of the local-minimum escape (a tangent-bug move along the nearest
/// obstacle's boundary), as summaries report it.
pub const ESCAPE_STRATEGY: &str = "boundary-following";

/// Closest the boundary-following escape goes to an obstacle (m).
const MIN_FOLLOW_CLEARANCE_M: f64 = 0.05;

/// Tangent-bug escape: walk along the level set of the map's distance field
/// (so round a cluster of obstacles as one), keeping the obstacles on the
/// `side` (+1: on the left), until closer to the target than the
/// stall point with the field pointing onwards. `None` when it cannot get
/// past within `budget` steps. `keep` is the footprint clearance to hold and
/// `margin` how much closer than the stall it must get before leaving (m).
#[allow(clippy::too_many_arguments)]
fn follow_boundary(
    map: &Map,
    start: Vec2,
    target: &Target,
    footprint_radius_m: f64,
    kind: FieldKind,
    p: &ApfParams,
    side: f64,
    keep: f64,
    margin: f64,
    budget: usize,
) -> Option<Vec<Vec2>> {
    let d_stall = (target.position - start).norm();
    let keep = keep.max(MIN_FOLLOW_CLEARANCE_M);
    let mut q = start;
    let mut seg = Vec::new();
    let limit = budget.min(((4.0 * std::f64::consts::PI * p.rho0_m + 60.0) / p.step_m) as usize);
    for _ in 0..limit {
        let nb = map.nearest(q);
        let c = nb.distance - footprint_radius_m;
        let dir = perp(nb.normal) * side + nb.normal * ((keep - c) / p.step_m).clamp(-1.0, 1.0);
        let next = q + dir.normalize() * p.step_m;
        if map.clearance(next, footprint_radius_m) <= 0.0 {
            return None;
        }
        q = next;
        seg.push(q);
        let dg = (target.position - q).norm();
        if dg <= p.goal_tolerance_m {
            return Some(seg);
        }
        if dg < d_stall - margin {
            let f = field_force(map, q, target, footprint_radius_m, kind, p);
            let nb = map.nearest(q);
            if f.dot(&(target.position - q)) > 0.0 && f.dot(&nb.normal) >= 0.0 {
                return Some(seg);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{Obstacle, Shape};
    use approx::assert_relative_eq;
    use autoshovel_core::{angle_diff, rad};

    fn open_map() -> Map {
        Map::new(Vec2::new(-50.0, -50.0), Vec2::new(50.0, 50.0))
    }

    #[test]
    fn classic_force_without_obstacles_is_the_attraction_of_eq_2() {
        let p = ApfParams::classic();
        let t = Target {
            position: Vec2::new(10.0, 0.0),
            motion_heading_rad: 0.0,
        };
        let f = field_force(
            &open_map(),
            Vec2::new(0.0, 0.0),
            &t,
            1.0,
            FieldKind::Classic,
            &p,
        );
        assert_relative_eq!(f, Vec2::new(10.0 * p.eta, 0.0), epsilon = 1e-12);
    }

    #[test]
    fn improved_repulsion_is_minus_the_gradient_of_eq_9() {
        // Closed form check by finite differences of U_rep1 = ½k(1/ρ−1/ρ0)²(ρt/ρd)^n.
        let p = ApfParams {
            mu: 0.0,
            eta: 1e-9,
            ..ApfParams::improved()
        };
        let mut map = open_map();
        map.obstacles.push(Obstacle {
            name: "rock".into(),
            shape: Shape::Circle {
                center: Vec2::new(3.0, 1.5),
                radius: 0.5,
            },
        });
        let t = Target {
            position: Vec2::new(8.0, 0.0),
            motion_heading_rad: 0.0,
        };
        let r_fp = 0.4;
        let u = |q: Vec2| {
            let rho = (q - Vec2::new(3.0, 1.5)).norm() - 0.5 - r_fp;
            let a = 1.0 / rho - 1.0 / p.rho0_m;
            let s = (t.position - q).norm() / p.rho_d_m;
            0.5 * p.k_rep * a * a * s.powf(p.n)
        };
        let q = Vec2::new(2.5, -0.2);
        let h = 1e-6;
        let grad = Vec2::new(
            (u(q + Vec2::new(h, 0.0)) - u(q - Vec2::new(h, 0.0))) / (2.0 * h),
            (u(q + Vec2::new(0.0, h)) - u(q - Vec2::new(0.0, h))) / (2.0 * h),
        );
        let f = field_force(&map, q, &t, r_fp, FieldKind::Improved, &p);
        // Subtract the (tiny) attraction.
        let att = (t.position - q) * p.eta;
        assert_relative_eq!(f - att, -grad, epsilon = 1e-5, max_relative = 1e-6);
    }

    #[test]
    fn virtual_obstacle_makes_the_machine_arrive_on_the_required_heading() {
        // Start beside the goal line; the required heading is +x.
        let p = ApfParams {
            lead_in_m: 0.0,
            ..ApfParams::improved()
        };
        let t = Target {
            position: Vec2::new(20.0, 0.0),
            motion_heading_rad: 0.0,
        };
        let d = descend(
            &open_map(),
            Vec2::new(0.0, 8.0),
            rad(-30.0),
            &t,
            1.0,
            FieldKind::Improved,
            &p,
        );
        assert!(d.stalled_at.is_none());
        let n = d.raw.len();
        let last = d.raw[n - 1] - d.raw[n - 8];
        let heading = last.y.atan2(last.x);
        assert!(
            angle_diff(heading, 0.0).abs() < rad(2.0),
            "arrival heading {} deg",
            heading.to_degrees()
        );
        // The classic field arrives along the straight line from the start instead.
        let c = descend(
            &open_map(),
            Vec2::new(0.0, 8.0),
            rad(-30.0),
            &t,
            1.0,
            FieldKind::Classic,
            &p,
        );
        let n = c.raw.len();
        let last = c.raw[n - 1] - c.raw[n - 8];
        assert!(angle_diff(last.y.atan2(last.x), 0.0).abs() > rad(15.0));
    }

    #[test]
    fn classic_field_stalls_in_front_of_a_wall_and_says_where() {
        // A wide polygon square across the way: the textbook local minimum.
        let mut map = open_map();
        let wall = crate::map::convex_polygon(vec![
            Vec2::new(8.0, -6.0),
            Vec2::new(9.0, -6.0),
            Vec2::new(9.0, 6.0),
            Vec2::new(8.0, 6.0),
        ])
        .unwrap();
        map.obstacles.push(Obstacle {
            name: "wall".into(),
            shape: Shape::Polygon { vertices: wall },
        });
        let t = Target {
            position: Vec2::new(16.0, 0.0),
            motion_heading_rad: 0.0,
        };
        let p = ApfParams::classic();
        let d = descend(
            &map,
            Vec2::new(0.0, 0.0),
            0.0,
            &t,
            1.0,
            FieldKind::Classic,
            &p,
        );
        let at = d
            .stalled_at
            .expect("classic APF must stall in front of the wall");
        assert!(at.x < 8.0 - 1.0 && at.y.abs() < 1.0, "stalled at {at:?}");
        // The improved planner escapes round it and reports it.
        let p = ApfParams::improved();
        let d = descend(
            &map,
            Vec2::new(0.0, 0.0),
            0.0,
            &t,
            1.0,
            FieldKind::Improved,
            &p,
        );
        assert!(
            d.stalled_at.is_none(),
            "improved stalled at {:?}",
            d.stalled_at
        );
        assert!(d.escapes >= 1);
        for q in &d.raw {
            assert!(map.clearance(*q, 1.0) > 0.0);
        }
    }
}
