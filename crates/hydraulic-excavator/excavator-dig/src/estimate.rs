//! What the planner makes of a contact: the force from the joint torques, the
//! rock's normal from the force, and an envelope for every boulder touched
//! (paper §2.2, [HE eq. 10]) — from what the machine measures, never from the
//! simulator's boulders.
//!
//! The paper assumes only that the direction of the force on the bucket tip
//! can be measured. Here the machine measures its joint torques (cylinder
//! pressures through the linkage), with noise, and knows its own joints, tip
//! and velocity. At a contact the torques jump; with the machine's own
//! Jacobian J, τ = … − Jᵀ·F ([`crate::dynamics`]), so the jump between the
//! sample before the contact and the contact gives
//!
//! ```text
//!     F̂ = argmin |Jᵀ·F + Δτ|  =  −(J·Jᵀ)⁻¹·J·Δτ        (least squares, 3 torques, 2 unknowns)
//! ```
//!
//! (the soil's share and the inertial terms barely change in one step).
//!
//! **The normal.** A rock pushes along its outward normal n, tilted by
//! Coulomb friction against the sliding direction t̂ (`soil`): F ∥ n − μ·t̂.
//! With a stated prior μ the planner turns F̂ back by atan μ towards the
//! tangential motion to get n̂ ([`normal_from_force`]); μ = 0 takes n̂ = F̂.
//! Where the approach is so nearly head-on that both turns fit the motion,
//! the force cannot tell them apart and n̂ = F̂ (off by at most atan μ).
//!
//! **The envelope.** One touch gives a point on the rim and its normal, not
//! the size. The planner assumes the size class the paper plans for: a hard
//! block larger than 30 % of the bucket, modelled as a disc of radius r
//! across the bucket's width b (the slice model of [HE eq. 2]; a sphere of
//! the paper's Ø 0.5 m would hold only 11 % of the 0.6 m³ bucket and fall out
//! of the class, the disc holds 33 %), so r ≥ r₃₀ = √(0.3·V_bucket/(π·b))
//! ([`BoulderPrior::from_bucket`]). The first estimate is the circle of the
//! prior radius behind the touch: c = p − r·n̂. Every further touch that lands
//! within reach of an estimate refines it by least squares over (c, r),
//! p_i = c + r·n̂_i, held towards the prior radius by a weak regulariser (two
//! touches with nearly parallel normals say little about r), never below r₃₀.
//! A touch far from every estimate starts a new boulder.

use autoshovel_core::Vec2;
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::Serialize;

use crate::kinematics::{Backhoe, Joints};
use crate::obstacle::Envelope;

/// The share of the bucket's volume above which the paper treats a hard
/// block as an obstacle to plan round.
pub const BOULDER_CLASS_SHARE: f64 = 0.3;

/// What the planner assumes about a boulder it has touched once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoulderPrior {
    /// Radius assumed for a boulder touched once; also the least radius a
    /// refined estimate may take (m).
    pub radius_m: f64,
    /// μ assumed between the tooth and rock, to turn the force into a normal.
    pub rock_friction: f64,
}

impl BoulderPrior {
    /// r₃₀ of the module docs: the radius of a disc across a bucket
    /// `width_m` wide holding 30 % of `capacity_m3`.
    pub fn class_radius_m(capacity_m3: f64, width_m: f64) -> f64 {
        (BOULDER_CLASS_SHARE * capacity_m3 / (std::f64::consts::PI * width_m)).sqrt()
    }

    /// The paper's class for this bucket, with friction `rock_friction`.
    pub fn from_bucket(capacity_m3: f64, width_m: f64, rock_friction: f64) -> Self {
        Self {
            radius_m: Self::class_radius_m(capacity_m3, width_m),
            rock_friction,
        }
    }
}

/// What the machine sensed at a contact: all the planner gets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Touch {
    /// Joints at the contact (encoders) (rad).
    pub q: Joints,
    /// The tooth tip, by forward kinematics (m).
    pub point: Vec2,
    /// V_c: the tip velocity (or its planned direction at rest) (m/s).
    pub velocity: Vec2,
    /// Measured joint torques at the contact (N·m).
    pub torques_nm: Joints,
    /// Measured joint torques one step before (N·m).
    pub torques_before_nm: Joints,
}

/// The tip force the torque jump of a touch implies (module docs) (N).
pub fn force_from_torques(machine: &Backhoe, touch: &Touch) -> Vec2 {
    let j = machine.jacobian(&touch.q); // 2 × 3
    let dtau: Vector3<f64> = touch.torques_nm - touch.torques_before_nm;
    let jjt: Matrix2<f64> = j * j.transpose();
    let rhs: Vector2<f64> = -(j * dtau);
    jjt.lu()
        .solve(&rhs)
        .map_or(Vec2::zeros(), |f| Vec2::new(f[0], f[1]))
}

/// The outward normal n̂ of the rock under a force `force` on a tip moving
/// with `velocity`, for friction μ (module docs). Unit length; the force's
/// own direction when μ = 0 or the tip does not slide.
pub fn normal_from_force(force: Vec2, velocity: Vec2, mu: f64) -> Vec2 {
    let f = force.normalize();
    if mu <= 0.0 {
        return f;
    }
    let phi = mu.atan();
    let rot = |a: f64| {
        let (s, c) = a.sin_cos();
        Vec2::new(c * f.x - s * f.y, s * f.x + c * f.y)
    };
    // The candidate n for which (n − μ t̂(n)) points along F̂ (t̂ the
    // tangential part of the velocity at n): the force turned by ±atan μ.
    let residual = |n: Vec2| {
        let tangential = velocity - n * velocity.dot(&n);
        let t = tangential.norm();
        if t <= 1e-12 * velocity.norm().max(1e-300) {
            return f64::INFINITY;
        }
        let pushed = (n - tangential / t * mu).normalize();
        (pushed - f).norm()
    };
    let (a, b) = (rot(phi), rot(-phi));
    let (ra, rb) = (residual(a), residual(b));
    // Both consistent (the tip slides one way relative to one candidate and
    // the other way relative to the other: a nearly head-on approach), or
    // neither: the force alone cannot tell; take its own direction, within
    // atan μ of either.
    let tolerance = 0.05 * mu.atan();
    if (ra < tolerance && rb < tolerance) || (ra.is_infinite() && rb.is_infinite()) {
        f
    } else if ra <= rb {
        a
    } else {
        b
    }
}

/// One boulder as the planner believes it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoulderEstimate {
    /// The envelope planned round (m).
    pub envelope: Envelope,
    /// Every touch on it: (point, estimated normal).
    pub touches: Vec<([f64; 2], [f64; 2])>,
}

/// Every boulder touched so far, as estimated.
#[derive(Debug, Clone, Default)]
pub struct Estimates {
    boulders: Vec<BoulderEstimate>,
}

impl Estimates {
    /// The envelopes believed, in the order first touched.
    pub fn envelopes(&self) -> Vec<Envelope> {
        self.boulders.iter().map(|b| b.envelope).collect()
    }

    /// Every estimate, in the order first touched.
    pub fn boulders(&self) -> &[BoulderEstimate] {
        &self.boulders
    }

    /// The estimate `index`.
    pub fn get(&self, index: usize) -> &BoulderEstimate {
        &self.boulders[index]
    }

    /// Adds a touch at `point` with estimated normal `normal`: it refines the
    /// estimate it lands within `reach_m` of (the nearest), its radius kept
    /// within [prior, `max_radius_m`], or starts a new one. Returns the
    /// estimate's index.
    pub fn add(
        &mut self,
        point: Vec2,
        normal: Vec2,
        prior: &BoulderPrior,
        reach_m: f64,
        max_radius_m: f64,
    ) -> usize {
        let nearest = self
            .boulders
            .iter()
            .enumerate()
            .map(|(i, b)| (i, b.envelope.signed_distance(point)))
            .filter(|(_, d)| *d <= reach_m)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i);
        let touch = ([point.x, point.y], [normal.x, normal.y]);
        match nearest {
            Some(i) => {
                let b = &mut self.boulders[i];
                b.touches.push(touch);
                b.envelope = fit_envelope(&b.touches, prior, max_radius_m);
                i
            }
            None => {
                self.boulders.push(BoulderEstimate {
                    envelope: behind(point, normal, prior.radius_m),
                    touches: vec![touch],
                });
                self.boulders.len() - 1
            }
        }
    }
}

/// The circle of radius `r` whose rim passes `point` with outward normal `normal`.
fn behind(point: Vec2, normal: Vec2, r: f64) -> Envelope {
    Envelope::new(point - normal * r, r)
}

/// Least squares over (c, r) of p_i = c + r·n_i, with a weak pull of r
/// towards the prior, r within [prior, `max_radius_m`] (module docs).
pub fn fit_envelope(
    touches: &[([f64; 2], [f64; 2])],
    prior: &BoulderPrior,
    max_radius_m: f64,
) -> Envelope {
    // Normal equations of the unknowns (c_x, c_y, r): each touch adds two rows
    // [1 0 n_x | p_x] and [0 1 n_y | p_y]; the prior adds λ·[0 0 1 | r_prior].
    let lambda = 0.05;
    let mut a = Matrix3::<f64>::zeros();
    let mut b = Vector3::<f64>::zeros();
    for (p, n) in touches {
        for k in 0..2 {
            let mut row = Vector3::zeros();
            row[k] = 1.0;
            row[2] = n[k];
            a += row * row.transpose();
            b += row * p[k];
        }
    }
    a[(2, 2)] += lambda;
    b[2] += lambda * prior.radius_m;
    let Some(x) = a.lu().solve(&b) else {
        let (p, n) = touches[0];
        return behind(Vec2::new(p[0], p[1]), Vec2::new(n[0], n[1]), prior.radius_m);
    };
    let r = x[2].clamp(prior.radius_m, max_radius_m.max(prior.radius_m));
    if r == x[2] {
        return Envelope::new(Vec2::new(x[0], x[1]), r);
    }
    // r held at a bound: the centre alone, c = mean(p_i − r·n_i).
    let k = touches.len() as f64;
    let c = touches.iter().fold(Vec2::zeros(), |s, (p, n)| {
        s + (Vec2::new(p[0], p[1]) - Vec2::new(n[0], n[1]) * r) / k
    });
    Envelope::new(c, r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    use crate::dynamics::Dynamics;
    use crate::profile::MachineProfile;
    use crate::soil::Soil;

    fn prior() -> BoulderPrior {
        BoulderPrior::from_bucket(0.6, 1.0, 0.3)
    }

    #[test]
    fn the_papers_boulder_is_just_in_the_class_as_a_disc() {
        let r30 = BoulderPrior::class_radius_m(0.6, 1.0);
        assert_relative_eq!(r30, (0.18 / std::f64::consts::PI).sqrt(), epsilon = 1e-15);
        assert!(r30 < 0.25, "Ø 0.5 m is above the 30 % class");
        // As a sphere it would not be.
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * 0.25f64.powi(3);
        assert!(sphere < 0.3 * 0.6);
    }

    #[test]
    fn the_torque_jump_gives_back_the_force() {
        let profile = MachineProfile::excavator_15t();
        let d = Dynamics::new(&profile);
        let m = Backhoe::new(&profile);
        let q = Joints::new(0.3, -1.8, -1.4);
        let (qd, qdd) = (Joints::new(0.05, -0.2, 0.1), Joints::zeros());
        let soil = Vec2::new(8_000.0, 2_000.0);
        let rock = Vec2::new(30_000.0, 95_000.0);
        let before = d.inverse_dynamics(&q, &qd, &qdd, 500.0, soil);
        let at = d.inverse_dynamics(&q, &qd, &qdd, 500.0, soil + rock);
        let touch = Touch {
            q,
            point: Vec2::zeros(),
            velocity: Vec2::new(-1.0, 0.0),
            torques_nm: at,
            torques_before_nm: before,
        };
        assert_relative_eq!(force_from_torques(&m, &touch), rock, max_relative = 1e-9);
    }

    #[test]
    fn the_normal_is_recovered_from_a_force_with_friction() {
        let soil = Soil {
            cutting_resistance_pa: 0.0,
            normal_ratio: 0.0,
            density_kg_m3: 0.0,
            rock_friction: 0.3,
        };
        let mut exact = 0;
        for deg in [10.0f64, 60.0, 100.0, 170.0, 230.0, 300.0] {
            let n = Vec2::new(deg.to_radians().cos(), deg.to_radians().sin());
            let v = Vec2::new(-1.0, -0.35);
            if v.dot(&n) >= 0.0 {
                continue; // a tip moving away from the rock does not touch it
            }
            let f = soil.contact_force(n, v, 1e5);
            let got = normal_from_force(f, v, 0.3);
            // Exact, or — where the approach is head-on enough that both
            // turns of the force fit — the force's own direction, within atan μ.
            if (got - n).norm() > 1e-9 {
                assert_relative_eq!(got, f.normalize(), epsilon = 1e-12);
                assert!(got.dot(&n).acos() <= 0.3f64.atan() + 1e-9);
            } else {
                exact += 1;
            }
        }
        assert!(exact >= 3, "{exact}");
    }

    #[test]
    fn touches_on_a_circle_give_it_back() {
        let truth = Envelope::new(Vec2::new(6.0, -0.6), 0.4);
        let p = prior();
        let mut est = Estimates::default();
        let on = |deg: f64| {
            let n = Vec2::new(deg.to_radians().cos(), deg.to_radians().sin());
            (truth.center() + n * truth.radius_m, n)
        };
        let (a, na) = on(60.0);
        assert_eq!(est.add(a, na, &p, 0.3, 1.0), 0);
        // One touch: the prior radius behind the touch point.
        let e = est.get(0).envelope;
        assert_relative_eq!(e.radius_m, p.radius_m);
        assert_relative_eq!(e.signed_distance(a), 0.0, epsilon = 1e-12);
        let (b, nb) = on(140.0);
        assert_eq!(est.add(b, nb, &p, 0.3, 1.0), 0);
        let e = est.get(0).envelope;
        assert!((e.radius_m - 0.4).abs() < 0.01, "{e:?}");
        assert!((e.center() - truth.center()).norm() < 0.01, "{e:?}");
        // A touch far away is another boulder.
        assert_eq!(
            est.add(Vec2::new(3.0, -0.5), Vec2::new(0.0, 1.0), &p, 0.3, 1.0),
            1
        );
    }
}
