//! Pieces of a planned bucket motion, each starting and ending at rest: a
//! joint-space quintic (level 1, [HE eq. 1]) or a smoothed detour round a boulder
//! (level 2), and their state at any time.
//!
//! A detour is a clamped cubic B-spline p(u) of the tooth tip, u ∈ [0, 1],
//! driven by the same zero-boundary quintic blend u = s(t/T), with the
//! attitude φ held at its value at the contact. Its joints come from the
//! inverse kinematics; rates from the extended Jacobian J_e = [J; 1 1 1]
//! (tip velocity and φ̇ = 0): J_e q̇ = (ṗ, 0), J_e q̈ = (p̈ − J̇q̇, 0), with
//! J̇q̇ = −Σₖ aₖ ωₖ² eₖ the velocity-product part of the tip acceleration.

use autoshovel_core::{CubicBSpline, Vec2};
use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

use crate::kinematics::{Backhoe, Joints};
use crate::quintic::{blend, JointQuintic};

/// What a segment does in the dig.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SegmentKind {
    /// Level 1: from the start (or a detour's end) down to the midpoint at the dig depth.
    Descent,
    /// Level 1: up to the end point on the ground.
    Rise,
    /// Level 2: round a boulder.
    Detour,
}

impl SegmentKind {
    /// Its name in tables and summaries (`descent`, `rise`, `detour`), as
    /// serialised.
    pub fn name(self) -> &'static str {
        match self {
            SegmentKind::Descent => "descent",
            SegmentKind::Rise => "rise",
            SegmentKind::Detour => "detour",
        }
    }
}

/// The state of the front at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionState {
    /// Joints (rad).
    pub q: Joints,
    /// Joint rates (rad/s).
    pub qd: Joints,
    /// Joint accelerations (rad/s²).
    pub qdd: Joints,
    /// Tooth tip (m).
    pub tip: Vec2,
    /// Tip velocity (m/s).
    pub tip_velocity: Vec2,
    /// Unit direction of motion, defined even at rest (the path's tangent).
    pub direction: Vec2,
}

/// A detour: the smoothed tip path at a fixed attitude.
#[derive(Debug, Clone)]
pub struct DetourMotion {
    /// p(u).
    pub spline: CubicBSpline,
    d1: CubicBSpline,
    d2: CubicBSpline,
    /// φ held along the detour (rad).
    pub attitude_rad: f64,
    /// T (s).
    pub duration_s: f64,
}

/// How a segment moves.
#[derive(Debug, Clone)]
pub enum Motion {
    /// Level 1 quintic in joint space.
    Joint(JointQuintic),
    /// Level 2 detour.
    Detour(DetourMotion),
}

/// One piece of the bucket's motion.
#[derive(Debug, Clone)]
pub struct Segment {
    /// Its role.
    pub kind: SegmentKind,
    /// Its motion.
    pub motion: Motion,
}

impl Segment {
    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        match &self.motion {
            Motion::Joint(j) => j.duration_s,
            Motion::Detour(d) => d.duration_s,
        }
    }

    /// State at local time t ∈ [0, T].
    pub fn state(&self, machine: &Backhoe, t: f64) -> MotionState {
        match &self.motion {
            Motion::Joint(j) => {
                let (q, qd, qdd) = j.state(t);
                let jac = machine.jacobian(&q);
                let tip = machine.forward(&q).point;
                let dir = jac * (j.q1 - j.q0);
                MotionState {
                    q,
                    qd,
                    qdd,
                    tip,
                    tip_velocity: jac * qd,
                    direction: unit(dir),
                }
            }
            Motion::Detour(d) => d.state(machine, t),
        }
    }

    /// The tip at time t (cheaper than [`Segment::state`]).
    pub fn tip(&self, machine: &Backhoe, t: f64) -> Vec2 {
        match &self.motion {
            Motion::Joint(j) => machine.forward(&j.state(t).0).point,
            Motion::Detour(d) => d.spline.point(blend(t / d.duration_s)[0]),
        }
    }

    /// Tip positions at `n + 1` instants evenly spaced in time (the paper's sampling).
    pub fn sample_tips(&self, machine: &Backhoe, n: usize) -> Vec<Vec2> {
        let t = self.duration_s();
        (0..=n)
            .map(|k| self.tip(machine, t * k as f64 / n as f64))
            .collect()
    }

    /// Joints at the end.
    pub fn end_joints(&self, machine: &Backhoe) -> Joints {
        self.state(machine, self.duration_s()).q
    }
}

fn unit(v: Vec2) -> Vec2 {
    let n = v.norm();
    if n > 0.0 {
        v / n
    } else {
        Vec2::zeros()
    }
}

impl DetourMotion {
    /// A detour along `spline` at `attitude_rad`, timed so that no joint
    /// exceeds `fraction` of its speed limit (and at least `min_s` long).
    /// `None` where the path leaves the workspace (checked by the caller first).
    pub fn new(
        machine: &Backhoe,
        spline: CubicBSpline,
        attitude_rad: f64,
        fraction: f64,
        min_s: f64,
    ) -> Option<Self> {
        let d1 = spline.derivative()?;
        let d2 = d1.derivative().unwrap_or_else(|| {
            CubicBSpline::clamped(vec![Vec2::zeros(), Vec2::zeros()]).expect("two points")
        });
        // The joint rates are dq/du · ds/dτ / T with u = s(τ): T is the
        // largest |dq/du(s(τ))|·s′(τ) / (fraction · limit) over τ.
        let n = 200;
        let speed = machine.limits.speed_rad_s;
        let mut duration_s = min_s;
        for k in 0..=n {
            let [u, us, _] = blend(k as f64 / n as f64);
            let q = machine
                .inverse_unchecked(spline.point(u), attitude_rad)
                .ok()?;
            let dq = joint_rates(machine, &q, d1.point(u))?;
            for i in 0..3 {
                duration_s = duration_s.max(dq[i].abs() * us / (fraction * speed[i]));
            }
        }
        Some(Self {
            spline,
            d1,
            d2,
            attitude_rad,
            duration_s,
        })
    }

    fn state(&self, machine: &Backhoe, t: f64) -> MotionState {
        let [u, us, uss] = blend(t / self.duration_s);
        let (ud, udd) = (
            us / self.duration_s,
            uss / (self.duration_s * self.duration_s),
        );
        let p = self.spline.point(u);
        let p1 = self.d1.point(u);
        let p2 = self.d2.point(u);
        let q = machine
            .inverse_unchecked(p, self.attitude_rad)
            .expect("a detour is checked reachable when planned");
        let v = p1 * ud;
        let a = p2 * ud * ud + p1 * udd;
        let qd = joint_rates(machine, &q, v).expect("the arm is not singular on a checked path");
        let bias = velocity_product(machine, &q, &qd);
        let qdd = joint_rates(machine, &q, a - bias).expect("not singular");
        MotionState {
            q,
            qd,
            qdd,
            tip: p,
            tip_velocity: v,
            direction: unit(p1),
        }
    }
}

/// Joint rates giving tip velocity `v` with the attitude held: J_e q̇ = (v, 0).
fn joint_rates(machine: &Backhoe, q: &Joints, v: Vec2) -> Option<Joints> {
    let j = machine.jacobian(q);
    let je = Matrix3::new(
        j[(0, 0)],
        j[(0, 1)],
        j[(0, 2)],
        j[(1, 0)],
        j[(1, 1)],
        j[(1, 2)],
        1.0,
        1.0,
        1.0,
    );
    je.lu().solve(&Vector3::new(v.x, v.y, 0.0))
}

/// J̇q̇ of the tip: −Σₖ aₖ ωₖ² eₖ.
fn velocity_product(machine: &Backhoe, q: &Joints, qd: &Joints) -> Vec2 {
    let a = machine.lengths();
    let mut phi = 0.0;
    let mut w = 0.0;
    let mut acc = Vec2::zeros();
    for k in 0..3 {
        phi += q[k];
        w += qd[k];
        acc -= Vec2::new(phi.cos(), phi.sin()) * (a[k] * w * w);
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::MachineProfile;
    use approx::assert_relative_eq;

    #[test]
    fn a_detour_state_is_consistent_with_finite_differences() {
        let m = Backhoe::new(&MachineProfile::excavator_15t());
        let ctrl = vec![
            Vec2::new(6.0, -0.4),
            Vec2::new(6.0, -0.3),
            Vec2::new(5.9, -0.2),
            Vec2::new(5.7, -0.2),
            Vec2::new(5.6, -0.3),
        ];
        let spline = CubicBSpline::clamped(ctrl).unwrap();
        let d = DetourMotion::new(&m, spline, -2.2, 0.5, 0.5).unwrap();
        let seg = Segment {
            kind: SegmentKind::Detour,
            motion: Motion::Detour(d),
        };
        let t_end = seg.duration_s();
        let h = 1e-5;
        for k in 1..10 {
            let t = t_end * k as f64 / 10.0;
            let s = seg.state(&m, t);
            let (a, b) = (seg.state(&m, t - h), seg.state(&m, t + h));
            assert_relative_eq!(s.qd, (b.q - a.q) / (2.0 * h), epsilon = 1e-6);
            assert_relative_eq!(s.qdd, (b.qd - a.qd) / (2.0 * h), epsilon = 1e-5);
            assert_relative_eq!(s.q.sum(), -2.2, epsilon = 1e-12);
            assert_relative_eq!(m.forward(&s.q).point, s.tip, epsilon = 1e-12);
        }
        let end = seg.state(&m, t_end);
        assert_relative_eq!(end.qd.norm(), 0.0, epsilon = 1e-12);
    }
}
