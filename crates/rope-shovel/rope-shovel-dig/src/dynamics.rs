//! Lagrange dynamics of the handle and dipper (rope-shovel paper §2.3,
//! [RS eqs. 9–10]) and the digging resistance (SPEC §4.2).
//!
//! # Model
//! Generalised coordinates θ₁ and the extension D = d₂ + d₂₀ (the paper's d).
//! The handle is a uniform rod of mass m_d and length L_d on the axis, from
//! D − L_d to D; the dipper with the material dug so far is a body of mass
//! m_c = m_dipper + ρV(t) whose centroid sits at (D − L_c/2) along the axis and
//! l₃/2 off it, between the axis and the teeth, with the inertia of an
//! L_c × l₃ plate. With a point at (s along u, e along n), ∂/∂θ₁ of its
//! position is s·n − e·u and ∂/∂D is u, so the Lagrangian L = K − P gives
//!
//! ```text
//!     M(D) = [ I(D)     −m_c e ]      I(D) = m_d((D − L_d/2)² + L_d²/12)
//!            [ −m_c e   m_d+m_c ]            + m_c((D − L_c/2)² + e²) + I_c
//!     I(D) θ̈ − m_c e D̈ + I′(D) Ḋ θ̇ + ∂P/∂θ = Q_θ
//!     −m_c e θ̈ + (m_d+m_c) D̈ − ½ I′(D) θ̇² + ∂P/∂D = Q_D                 ([RS eq. 10])
//! ```
//!
//! With e = 0 and the dipper as a rod from D to D + L_c this is exactly the
//! printed [RS eq. 10] (whose gravity term says L_d/2 where the rod's own L_c/2
//! belongs; the test `reduces_to_printed_eq_10` checks the reduction).
//! Generalised forces come from virtual work, Q = Jᵀ F at each point of
//! application: the hoist rope tension F_h at the bail pin C along the rope,
//! the crowd force F_c along the handle (conjugate to D), and the digging
//! resistance at the tip — tangential F_τ = k_F·b·c against the tip velocity
//! and normal F_n = ψ·F_τ pushing the tip out of the uncut bank (towards the
//! machine's side of the path). Solving the two equations for F_h and F_c is
//! the inverse dynamics. The accretion of material is quasi-static (the ṁ·v
//! reaction, below 0.01 N on the scale model, is left out).

use crate::kinematics::{JointState, RopeShovel};
use crate::profile::MachineProfile;

use autoshovel_core::G;

/// Mass properties of the moving front end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassModel {
    /// m_d (kg).
    pub handle_mass: f64,
    /// L_d (m).
    pub handle_length: f64,
    /// Empty dipper (kg).
    pub dipper_mass: f64,
    /// L_c (m).
    pub dipper_length: f64,
    /// Dipper centroid offset e off the handle axis (m).
    pub dipper_offset: f64,
}

impl MassModel {
    /// From a profile (e = l₃/2).
    pub fn of(profile: &MachineProfile) -> Self {
        let g = profile.geometry();
        Self {
            handle_mass: profile.handle.mass_kg,
            handle_length: profile.handle.length_m,
            dipper_mass: profile.dipper.mass_kg,
            dipper_length: profile.dipper.length_m,
            dipper_offset: 0.5 * g.l3,
        }
    }

    /// M(D), I′(D) = ∂I/∂D and the gravity terms (∂P/∂θ, ∂P/∂D) for a dipper
    /// carrying `m_load` kg of material.
    #[inline]
    pub fn terms(&self, theta1: f64, d: f64, m_load: f64) -> LagrangeTerms {
        let (sn, cs) = theta1.sin_cos();
        self.terms_sc(sn, cs, d, m_load)
    }

    /// [`MassModel::terms`] from sin θ₁ and cos θ₁.
    #[inline]
    pub fn terms_sc(&self, sn: f64, cs: f64, d: f64, m_load: f64) -> LagrangeTerms {
        let (md, ld) = (self.handle_mass, self.handle_length);
        let mc = self.dipper_mass + m_load;
        let (lc, e) = (self.dipper_length, self.dipper_offset);
        let s_h = d - 0.5 * ld;
        let s_c = d - 0.5 * lc;
        let ic = mc * (lc * lc + 4.0 * e * e) / 12.0;
        let inertia = md * (s_h * s_h + ld * ld / 12.0) + mc * (s_c * s_c + e * e) + ic;
        let inertia_d = 2.0 * md * s_h + 2.0 * mc * s_c;
        // y of a point (s, e) is l₂ − s cos θ + e sin θ.
        let dp_dtheta = G * (md * s_h * sn + mc * (s_c * sn + e * cs));
        let dp_dd = -G * (md + mc) * cs;
        LagrangeTerms {
            m11: inertia,
            m12: -mc * e,
            m22: md + mc,
            inertia_d,
            dp_dtheta,
            dp_dd,
        }
    }

    /// Kinetic plus potential energy (zero of potential at the saddle height).
    pub fn energy(&self, theta1: f64, d: f64, theta_dot: f64, d_dot: f64, m_load: f64) -> f64 {
        let t = self.terms(theta1, d, m_load);
        let kinetic = 0.5
            * (t.m11 * theta_dot * theta_dot
                + 2.0 * t.m12 * theta_dot * d_dot
                + t.m22 * d_dot * d_dot);
        let (md, ld) = (self.handle_mass, self.handle_length);
        let mc = self.dipper_mass + m_load;
        let (sn, cs) = theta1.sin_cos();
        let y = |s: f64, e: f64| -s * cs + e * sn;
        let potential = G
            * (md * y(d - 0.5 * ld, 0.0)
                + mc * y(d - 0.5 * self.dipper_length, self.dipper_offset));
        kinetic + potential
    }
}

/// The pieces of [RS eq. 10] at one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LagrangeTerms {
    /// M₁₁ = I(D).
    pub m11: f64,
    /// M₁₂ = M₂₁.
    pub m12: f64,
    /// M₂₂ = m_d + m_c.
    pub m22: f64,
    /// I′(D).
    pub inertia_d: f64,
    /// ∂P/∂θ₁.
    pub dp_dtheta: f64,
    /// ∂P/∂D.
    pub dp_dd: f64,
}

/// Forces, speeds and powers of the hoist and crowd at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Drive {
    /// Hoist rope tension F_h (N).
    pub hoist_force_n: f64,
    /// Crowd force F_c along the handle (N).
    pub crowd_force_n: f64,
    /// Hoist rope speed v_h, positive when hoisting (rope shortening) (m/s).
    pub hoist_speed_m_s: f64,
    /// Crowd speed v_c = ḋ₂, positive when crowding out (m/s).
    pub crowd_speed_m_s: f64,
    /// θ₂: angle between the rope and the handle (rad).
    pub rope_handle_angle_rad: f64,
    /// Tangential digging resistance F_τ (N).
    pub resistance_tangential_n: f64,
    /// Normal digging resistance F_n (N).
    pub resistance_normal_n: f64,
}

impl Drive {
    /// Hoist power P_h = F_h v_h (W).
    pub fn hoist_power_w(&self) -> f64 {
        self.hoist_force_n * self.hoist_speed_m_s
    }
    /// Crowd power P_c = F_c v_c (W).
    pub fn crowd_power_w(&self) -> f64 {
        self.crowd_force_n * self.crowd_speed_m_s
    }
}

/// Inverse dynamics ([RS eqs. 9–10]): the hoist and crowd forces that drive the joint state
/// `js` against gravity, inertia and a digging resistance `f_tau` (with
/// normal ratio `psi`), for `m_load` kg in the dipper. The tip velocity
/// `tip_v` orients the resistance. `None` where the rope has no moment arm
/// (θ₂ = 0) or the bail pin is inside the sheave.
#[inline]
pub fn inverse_dynamics(
    shovel: &RopeShovel,
    mass: &MassModel,
    js: &JointState,
    tip_v: [f64; 2],
    f_tau: f64,
    psi: f64,
    m_load: f64,
) -> Option<Drive> {
    let g = &shovel.geometry;
    let d = js.q.d2 + g.d20;
    let (u, n) = (js.u, js.n);
    let t = mass.terms_sc(u[0], n[0], d, m_load);
    let (th_dot, d_dot) = (js.theta1_dot, js.d2_dot);
    // [RS eq. 9]–[RS eq. 10]: the generalised forces of the Lagrange equations.
    let q_theta =
        t.m11 * js.theta1_ddot + t.m12 * js.d2_ddot + t.inertia_d * d_dot * th_dot + t.dp_dtheta;
    let q_d =
        t.m12 * js.theta1_ddot + t.m22 * js.d2_ddot - 0.5 * t.inertia_d * th_dot * th_dot + t.dp_dd;

    // Digging resistance at the tip (s = D, e = l₃).
    let speed = (tip_v[0] * tip_v[0] + tip_v[1] * tip_v[1]).sqrt();
    let (mut qdig_theta, mut qdig_d) = (0.0, 0.0);
    if f_tau > 0.0 && speed > 0.0 {
        let tv = [tip_v[0] / speed, tip_v[1] / speed];
        let left = [-tv[1], tv[0]]; // towards the machine's side of the path
        let f = [
            -f_tau * tv[0] + psi * f_tau * left[0],
            -f_tau * tv[1] + psi * f_tau * left[1],
        ];
        let j_theta = [d * n[0] - g.l3 * u[0], d * n[1] - g.l3 * u[1]];
        qdig_theta = j_theta[0] * f[0] + j_theta[1] * f[1];
        qdig_d = u[0] * f[0] + u[1] * f[1];
    }
    // Hoist rope at the bail pin C (s = D − bail_behind_tip, e = 0).
    let c = shovel.bail_at(u, js.q.d2);
    let (rope, _) = shovel.rope(c)?;
    let s_c = d - g.bail_behind_tip;
    let h_theta = s_c * (n[0] * rope[0] + n[1] * rope[1]);
    let h_d = u[0] * rope[0] + u[1] * rope[1];
    if h_theta.abs() < 1e-9 {
        return None;
    }
    let hoist = (q_theta - qdig_theta) / h_theta;
    let crowd = q_d - qdig_d - hoist * h_d;
    // v_C · rope: rate at which the rope shortens.
    let v_c_point = [
        s_c * th_dot * n[0] + d_dot * u[0],
        s_c * th_dot * n[1] + d_dot * u[1],
    ];
    let hoist_speed = v_c_point[0] * rope[0] + v_c_point[1] * rope[1];
    Some(Drive {
        hoist_force_n: hoist,
        crowd_force_n: crowd,
        hoist_speed_m_s: hoist_speed,
        crowd_speed_m_s: d_dot,
        rope_handle_angle_rad: (-h_d).clamp(-1.0, 1.0).acos(),
        resistance_tangential_n: f_tau,
        resistance_normal_n: psi * f_tau,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{handle_axes, Joints};
    use approx::assert_relative_eq;

    fn setup() -> (RopeShovel, MassModel) {
        let p = MachineProfile::scale_model();
        (RopeShovel::new(p.geometry()), MassModel::of(&p))
    }

    #[test]
    fn reduces_to_printed_eq_10() {
        // e = 0, dipper rod from D to D + L_c: shift the centroid by using
        // −L_c as the "length" (centroid D + L_c/2) and compare with [RS eq. 10]'s
        // inertia and Coriolis coefficients as printed.
        let m = MassModel {
            handle_mass: 0.5,
            handle_length: 0.45,
            dipper_mass: 1.3,
            dipper_length: -0.11,
            dipper_offset: 0.0,
        };
        let (d, th) = (0.3, 0.4);
        let t = m.terms(th, d, 0.0);
        let (md, ld, mc, lc) = (0.5, 0.45, 1.3, 0.11);
        let printed_inertia =
            md * (d * d - ld * d + ld * ld / 3.0) + mc * (d * d + lc * d + lc * lc / 3.0);
        assert_relative_eq!(t.m11, printed_inertia, epsilon = 1e-12);
        assert_relative_eq!(
            t.inertia_d,
            2.0 * d * (md + mc) - (md * ld - mc * lc),
            epsilon = 1e-12
        );
        let gravity = md * G * th.sin() * (d - ld / 2.0) + mc * G * th.sin() * (d + lc / 2.0);
        assert_relative_eq!(t.dp_dtheta, gravity, epsilon = 1e-12);
        assert_relative_eq!(t.dp_dd, -(md + mc) * G * th.cos(), epsilon = 1e-12);
    }

    /// Work of hoist and crowd over a motion equals the change in mechanical
    /// energy plus the work done against the digging resistance.
    #[test]
    fn motor_work_balances_energy_and_resistance() {
        let (s, m) = setup();
        let (tf, n) = (4.0, 40_000);
        let q = |t: f64| {
            let tau = t / tf;
            let sm = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
            (-0.1 + 1.0 * sm, 0.17 * sm)
        };
        let (f_tau, psi, load) = (30.0, 0.3, 0.7);
        let mut work = 0.0;
        let mut resist = 0.0;
        let h = tf / n as f64;
        let state = |t: f64| {
            let e = 1e-5;
            let (a0, b0) = q(t);
            let (ap, bp) = q(t + e);
            let (am, bm) = q(t - e);
            let (u, n) = handle_axes(a0);
            JointState {
                u,
                n,
                q: Joints { theta1: a0, d2: b0 },
                theta1_dot: (ap - am) / (2.0 * e),
                d2_dot: (bp - bm) / (2.0 * e),
                theta1_ddot: (ap - 2.0 * a0 + am) / (e * e),
                d2_ddot: (bp - 2.0 * b0 + bm) / (e * e),
            }
        };
        for i in 0..n {
            let t = (i as f64 + 0.5) * h;
            let js = state(t);
            let g = &s.geometry;
            let (u, nn) = handle_axes(js.q.theta1);
            let d = js.q.d2 + g.d20;
            let v = [
                js.theta1_dot * (d * nn[0] - g.l3 * u[0]) + js.d2_dot * u[0],
                js.theta1_dot * (d * nn[1] - g.l3 * u[1]) + js.d2_dot * u[1],
            ];
            let drive = inverse_dynamics(&s, &m, &js, v, f_tau, psi, load).unwrap();
            work += (drive.hoist_power_w() + drive.crowd_power_w()) * h;
            resist += f_tau * v[0].hypot(v[1]) * h; // F_n ⟂ v does no work
        }
        let e = |t: f64| {
            let js = state(t);
            m.energy(
                js.q.theta1,
                js.q.d2 + s.geometry.d20,
                js.theta1_dot,
                js.d2_dot,
                load,
            )
        };
        let delta = e(tf - 1e-4) - e(1e-4);
        assert_relative_eq!(work, delta + resist, max_relative = 1e-4);
    }
}
