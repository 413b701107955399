//! Lagrange dynamics of boom, stick and bucket (paper §1.1: "运用 D-H 法和拉格朗日
//! 方程法 … 建立挖掘机的运动学与动力学方程"), enough to report the joint torques.
//!
//! # Model
//! Each link i is a rigid body of mass mᵢ with its centroid cᵢ on the link
//! line, `centroid_m` from its own joint, and moment of inertia Iᵢ about the
//! centroid; the soil dug so far (mass m_L = ρ·V) rides as a point mass at the
//! bucket centroid. With the centroid Jacobians J_vᵢ = ∂cᵢ/∂q (2 × 3; column j ≤ i
//! is z × (cᵢ − pⱼ₋₁), with p₀ the boom foot) and J_ωᵢ = [1…1 0…] (the planar
//! link angle is θ₁ + … + θᵢ), the Lagrangian
//!
//! ```text
//!     L = Σᵢ ½ mᵢ |J_vᵢ q̇|² + ½ Iᵢ (J_ωᵢ q̇)² − mᵢ g y_cᵢ
//! ```
//!
//! gives d/dt ∂L/∂q̇ − ∂L/∂q = τ + Jᵀ F, that is
//!
//! ```text
//!     τ = M(q) q̈ + C(q, q̇) q̇ + G(q) − J(q)ᵀ F                       (Lagrange)
//!     M = Σᵢ mᵢ J_vᵢᵀ J_vᵢ + Iᵢ J_ωᵢᵀ J_ωᵢ,   G = Σᵢ mᵢ g J_vᵢᵀ ŷ,
//!     C q̇ = Σᵢ mᵢ J_vᵢᵀ (J̇_vᵢ q̇),   J̇_vᵢ q̇ = −Σ_{k≤i} ℓₖ ωₖ² eₖ
//! ```
//!
//! where F is the external force on the tooth tip (the digging resistance),
//! ωₖ = θ̇₁ + … + θ̇ₖ, eₖ the unit vector of link k and ℓₖ its length (aₖ for
//! k < i, the centroid distance for k = i). The C q̇ form is the Christoffel
//! form summed (the planar links' J_ω are constant, so rotation adds no
//! velocity product). The test `power_balances_energy_and_resistance_work`
//! checks it independently: ∫ τ·q̇ dt = Δ(KE + PE) + ∫ −F·v dt.

use autoshovel_core::Vec2;
use nalgebra::{Matrix2x3, Matrix3, Vector3};

use crate::kinematics::{Backhoe, Joints};
use crate::profile::MachineProfile;

use autoshovel_core::G;

/// Mass properties of the three links.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MassModel {
    /// mᵢ (kg).
    pub mass_kg: [f64; 3],
    /// Centroid distance from the link's own joint along the link (m).
    pub centroid_m: [f64; 3],
    /// Iᵢ about the centroid (kg·m²).
    pub inertia_kg_m2: [f64; 3],
}

impl MassModel {
    /// From a profile.
    pub fn of(profile: &MachineProfile) -> Self {
        let m = &profile.masses;
        Self {
            mass_kg: [m.boom_kg, m.stick_kg, m.bucket_kg],
            centroid_m: [m.boom_centroid_m, m.stick_centroid_m, m.bucket_centroid_m],
            inertia_kg_m2: [
                m.boom_inertia_kg_m2,
                m.stick_inertia_kg_m2,
                m.bucket_inertia_kg_m2,
            ],
        }
    }
}

/// Kinetic and potential energy at one state (J) (potential zero at y = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// ½ q̇ᵀ M q̇.
    pub kinetic_j: f64,
    /// Σ mᵢ g y_cᵢ.
    pub potential_j: f64,
}

/// The machine's front with its mass model.
#[derive(Debug, Clone)]
pub struct Dynamics {
    /// Kinematics.
    pub machine: Backhoe,
    /// Masses.
    pub mass: MassModel,
}

/// Per-link quantities at one configuration.
struct Links {
    /// Unit vectors eₖ of the links.
    e: [Vec2; 3],
    /// Centroid Jacobians.
    jv: [Matrix2x3<f64>; 3],
    /// Centroid heights.
    y: [f64; 3],
    /// Link masses with the load on the bucket.
    m: [f64; 3],
}

impl Dynamics {
    /// Kinematics and masses of a profile.
    pub fn new(profile: &MachineProfile) -> Self {
        Self {
            machine: Backhoe::new(profile),
            mass: MassModel::of(profile),
        }
    }

    fn links(&self, q: &Joints, load_kg: f64) -> Links {
        let a = self.machine.lengths();
        let c = self.mass.centroid_m;
        let phi = [q[0], q[0] + q[1], q[0] + q[1] + q[2]];
        let e = phi.map(|p| Vec2::new(p.cos(), p.sin()));
        let mut pins = [self.machine.foot(); 3];
        for k in 1..3 {
            pins[k] = pins[k - 1] + e[k - 1] * a[k - 1];
        }
        let centroids = [0, 1, 2].map(|i| pins[i] + e[i] * c[i]);
        let jv = [0, 1, 2].map(|i| {
            let mut j = Matrix2x3::zeros();
            for k in 0..=i {
                let r = centroids[i] - pins[k];
                j[(0, k)] = -r.y;
                j[(1, k)] = r.x;
            }
            j
        });
        let mut m = self.mass.mass_kg;
        m[2] += load_kg;
        Links {
            e,
            jv,
            y: centroids.map(|p| p.y),
            m,
        }
    }

    /// Inertia matrix M(q) with `load_kg` of soil in the bucket.
    pub fn mass_matrix(&self, q: &Joints, load_kg: f64) -> Matrix3<f64> {
        let l = self.links(q, load_kg);
        self.mass_matrix_of(&l)
    }

    fn mass_matrix_of(&self, l: &Links) -> Matrix3<f64> {
        let mut mm = Matrix3::zeros();
        for i in 0..3 {
            mm += l.jv[i].transpose() * l.jv[i] * l.m[i];
            // J_ωᵢᵀ J_ωᵢ: ones in the leading (i+1) × (i+1) block.
            for r in 0..=i {
                for s in 0..=i {
                    mm[(r, s)] += self.mass.inertia_kg_m2[i];
                }
            }
        }
        mm
    }

    /// Velocity-product torques C(q, q̇) q̇.
    pub fn coriolis(&self, q: &Joints, qd: &Joints, load_kg: f64) -> Vector3<f64> {
        let l = self.links(q, load_kg);
        self.coriolis_of(&l, qd)
    }

    fn coriolis_of(&self, l: &Links, qd: &Joints) -> Vector3<f64> {
        let a = self.machine.lengths();
        let c = self.mass.centroid_m;
        let w = [qd[0], qd[0] + qd[1], qd[0] + qd[1] + qd[2]];
        let mut h = Vector3::zeros();
        for i in 0..3 {
            let mut acc = Vec2::zeros();
            for k in 0..=i {
                let len = if k < i { a[k] } else { c[k] };
                acc -= l.e[k] * (len * w[k] * w[k]);
            }
            h += l.jv[i].transpose() * acc * l.m[i];
        }
        h
    }

    /// Gravity torques G(q) = ∂(potential)/∂q.
    pub fn gravity(&self, q: &Joints, load_kg: f64) -> Vector3<f64> {
        let l = self.links(q, load_kg);
        Self::gravity_of(&l)
    }

    fn gravity_of(l: &Links) -> Vector3<f64> {
        let mut g = Vector3::zeros();
        for i in 0..3 {
            g += l.jv[i].row(1).transpose() * (l.m[i] * G);
        }
        g
    }

    /// Joint torques τ (N·m) that move the front along (q, q̇, q̈) with
    /// `load_kg` in the bucket against the external tip force `tip_force`
    /// (the soil's push on the tooth, (N)).
    pub fn inverse_dynamics(
        &self,
        q: &Joints,
        qd: &Joints,
        qdd: &Joints,
        load_kg: f64,
        tip_force: Vec2,
    ) -> Joints {
        let l = self.links(q, load_kg);
        let mm = self.mass_matrix_of(&l);
        let h = self.coriolis_of(&l, qd);
        let g = Self::gravity_of(&l);
        let j = self.machine.jacobian(q);
        mm * qdd + h + g - j.transpose() * tip_force
    }

    /// Kinetic and potential energy.
    pub fn energy(&self, q: &Joints, qd: &Joints, load_kg: f64) -> Energy {
        let l = self.links(q, load_kg);
        let mm = self.mass_matrix_of(&l);
        Energy {
            kinetic_j: 0.5 * qd.dot(&(mm * qd)),
            potential_j: (0..3).map(|i| l.m[i] * G * l.y[i]).sum(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn dynamics() -> Dynamics {
        Dynamics::new(&MachineProfile::excavator_15t())
    }

    /// Static closed form: gravity torque about each joint is the weight of
    /// everything outboard times its horizontal lever arm.
    #[test]
    fn gravity_torques_are_the_weights_times_their_lever_arms() {
        let d = dynamics();
        let q = Joints::new(0.4, -1.9, -1.2);
        let load = 900.0;
        let g = d.gravity(&q, load);
        let a = d.machine.lengths();
        let c = d.mass.centroid_m;
        let foot = d.machine.foot();
        let phi = [q[0], q[0] + q[1], q[0] + q[1] + q[2]];
        let x_pin1 = foot.x + a[0] * phi[0].cos();
        let x_pin2 = x_pin1 + a[1] * phi[1].cos();
        let xc = [
            foot.x + c[0] * phi[0].cos(),
            x_pin1 + c[1] * phi[1].cos(),
            x_pin2 + c[2] * phi[2].cos(),
        ];
        let m = [1150.0, 560.0, 480.0 + load];
        let tau3 = m[2] * G * (xc[2] - x_pin2);
        let tau2 = m[1] * G * (xc[1] - x_pin1) + m[2] * G * (xc[2] - x_pin1);
        let tau1 = (0..3).map(|i| m[i] * G * (xc[i] - foot.x)).sum::<f64>();
        assert_relative_eq!(g[0], tau1, max_relative = 1e-12);
        assert_relative_eq!(g[1], tau2, max_relative = 1e-12);
        assert_relative_eq!(g[2], tau3, max_relative = 1e-12);
    }

    /// Static closed form of a tip force: τ = −r × F about each joint.
    #[test]
    fn a_static_tip_force_loads_each_joint_by_its_moment() {
        let d = dynamics();
        let q = Joints::new(0.1, -1.5, -1.4);
        let zero = Joints::zeros();
        let f = Vec2::new(30_000.0, -8_000.0);
        let tau = d.inverse_dynamics(&q, &zero, &zero, 0.0, f) - d.gravity(&q, 0.0);
        let [p1, p2, tip] = d.machine.joint_points(&q);
        for (i, pin) in [d.machine.foot(), p1, p2].into_iter().enumerate() {
            let r = tip - pin;
            assert_relative_eq!(tau[i], -(r.x * f.y - r.y * f.x), max_relative = 1e-12);
        }
    }

    #[test]
    fn the_mass_matrix_is_symmetric_positive_definite() {
        let d = dynamics();
        let m = d.mass_matrix(&Joints::new(0.2, -2.0, -0.5), 500.0);
        assert_relative_eq!(m, m.transpose(), epsilon = 1e-9);
        assert!(m.cholesky().is_some());
    }

    /// Power balance along a smooth motion with a resisting tip force:
    /// ∫ τ·q̇ dt = Δ(KE + PE) + ∫ −F·v dt (independent of how M, C, G were built).
    #[test]
    fn power_balances_energy_and_resistance_work() {
        let d = dynamics();
        let q0 = Joints::new(0.35, -1.4, -0.6);
        let dq = Joints::new(-0.5, -0.6, -1.6);
        let duration = 3.0;
        let load = 700.0;
        let state = |t: f64| {
            // q(t) = q0 + dq·(t/T − sin(2πt/T)/(2π)) plus a wobble, so that every
            // term of C and M matters.
            let w = 2.0 * std::f64::consts::PI / duration;
            let s = t / duration - (w * t).sin() / (2.0 * std::f64::consts::PI);
            let sd = (1.0 - (w * t).cos()) / duration;
            let sdd = w * (w * t).sin() / duration;
            let wob = Joints::new(0.05, -0.04, 0.08);
            let q = q0 + dq * s + wob * (1.3 * w * t).sin();
            let qd = dq * sd + wob * (1.3 * w * (1.3 * w * t).cos());
            let qdd = dq * sdd - wob * ((1.3 * w).powi(2) * (1.3 * w * t).sin());
            (q, qd, qdd)
        };
        let force = |q: &Joints, qd: &Joints| {
            let v = d.machine.jacobian(q) * qd;
            // Resistance against the motion and a push to its side.
            -v * 12_000.0 + Vec2::new(-v.y, v.x) * 3_000.0 + Vec2::new(0.0, 2_000.0)
        };
        let n = 20_000;
        let h = duration / n as f64;
        let (mut motor, mut resist) = (0.0, 0.0);
        for k in 0..n {
            // Simpson on each step.
            let (ta, tm, tb) = (k as f64 * h, (k as f64 + 0.5) * h, (k + 1) as f64 * h);
            let mut p = [0.0; 3];
            let mut r = [0.0; 3];
            for (i, t) in [ta, tm, tb].into_iter().enumerate() {
                let (q, qd, qdd) = state(t);
                let f = force(&q, &qd);
                let tau = d.inverse_dynamics(&q, &qd, &qdd, load, f);
                p[i] = tau.dot(&qd);
                r[i] = -f.dot(&(d.machine.jacobian(&q) * qd));
            }
            motor += h / 6.0 * (p[0] + 4.0 * p[1] + p[2]);
            resist += h / 6.0 * (r[0] + 4.0 * r[1] + r[2]);
        }
        let (qa, qda, _) = state(0.0);
        let (qb, qdb, _) = state(duration);
        let (ea, eb) = (d.energy(&qa, &qda, load), d.energy(&qb, &qdb, load));
        let delta = eb.kinetic_j + eb.potential_j - ea.kinetic_j - ea.potential_j;
        assert!(resist > 1_000.0, "the resistance does work: {resist}");
        assert_relative_eq!(motor, delta + resist, max_relative = 1e-8, epsilon = 1e-6);
    }
}
