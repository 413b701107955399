//! 1R-1P dipper kinematics of the rope shovel (rope-shovel paper §2.2,
//! [RS eqs. 1–8]), in the dig frame {Oo}: x from the toe into the pile, y up.
//!
//! Joint 1 turns the handle about the saddle centre O = (l₁, l₂) by θ₁, the
//! angle of the handle from the downward vertical (counter-clockwise, towards
//! the pile); joint 2 slides it out by d₂. With the handle direction
//! u = (sin θ₁, −cos θ₁) and its normal n = (cos θ₁, sin θ₁), the tooth tip is
//!
//! ```text
//!     p = O + l₃ n + (d₂ + d₂₀) u                                  ([RS eq. 6])
//! ```
//!
//! which [`RopeShovel::forward_poe`] builds as [RS eq. 1], e^{\[ξ₁\]θ₁} e^{\[ξ₂\]d₂} T(0),
//! from the twists ξ₁ (revolute about z through O) and ξ₂ (prismatic along
//! the handle at home, −y). The inverse is closed form ([RS eqs. 7–8], with atan2
//! so that every quadrant is right):
//!
//! ```text
//!     d₂ + d₂₀ = √(|p − O|² − l₃²),   θ₁ = atan2((p_y − l₂) l₃ + (p_x − l₁) D,
//!                                              (p_x − l₁) l₃ − (p_y − l₂) D)
//! ```
//!
//! Rates follow from the derivatives of [RS eq. 6] in the (n, u) basis:
//! ṗ_n = D θ̇₁, ṗ_u = Ḋ − l₃ θ̇₁, and
//! p̈_n = D θ̈₁ + 2 θ̇₁ Ḋ − l₃ θ̇₁², p̈_u = D̈ − l₃ θ̈₁ − D θ̇₁² (D = d₂ + d₂₀).

use autoshovel_core::poe::{product_of_exponentials, Twist};
use nalgebra::{Matrix4, Vector3};

use crate::profile::Geometry;

/// Joint values: handle angle θ₁ (rad) and extension d₂ (m) ([RS eq. 1]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Joints {
    /// θ₁: handle angle from the downward vertical, counter-clockwise (rad).
    pub theta1: f64,
    /// d₂: handle extension beyond the retracted d₂₀ (m).
    pub d2: f64,
}

/// Joint positions, velocities and accelerations at one instant.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct JointState {
    /// Positions.
    pub q: Joints,
    /// θ̇₁ (rad/s).
    pub theta1_dot: f64,
    /// ḋ₂, the crowd speed v_c (m/s).
    pub d2_dot: f64,
    /// θ̈₁ (rad/s²).
    pub theta1_ddot: f64,
    /// d̈₂ (m/s²).
    pub d2_ddot: f64,
    /// Handle direction u = (sin θ₁, −cos θ₁).
    pub u: [f64; 2],
    /// Handle normal n = (cos θ₁, sin θ₁).
    pub n: [f64; 2],
}

/// The 1R-1P front end of a rope shovel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RopeShovel {
    /// Derived geometry (see [`crate::profile`]).
    pub geometry: Geometry,
}

/// Unit vectors (u along the handle away from O, n its normal towards the
/// tip side) for a handle angle.
#[inline]
pub fn handle_axes(theta1: f64) -> ([f64; 2], [f64; 2]) {
    let (s, c) = theta1.sin_cos();
    ([s, -c], [c, s])
}

impl RopeShovel {
    /// The shovel of a geometry.
    pub fn new(geometry: Geometry) -> Self {
        Self { geometry }
    }

    /// [RS eq. 6]: the tooth tip for joint values (closed form).
    #[inline]
    pub fn forward(&self, q: Joints) -> [f64; 2] {
        let g = &self.geometry;
        // [RS eq. 3]: the translation column of T_BW(q), as the paper expands it.
        let (u, n) = handle_axes(q.theta1);
        let d = q.d2 + g.d20;
        [g.l1 + g.l3 * n[0] + d * u[0], g.l2 + g.l3 * n[1] + d * u[1]] // [RS eq. 6]
    }

    /// [RS eq. 1]: the full tip pose T_BW(q) = e^{\[ξ₁\]θ₁} e^{\[ξ₂\]d₂} T_BW(0) by PoE
    /// (z out of the dig plane). Its translation equals [`RopeShovel::forward`].
    pub fn forward_poe(&self, q: Joints) -> Matrix4<f64> {
        let g = &self.geometry;
        let xi1 = Twist::revolute(Vector3::z(), Vector3::new(g.l1, g.l2, 0.0));
        let xi2 = Twist::prismatic(Vector3::new(0.0, -1.0, 0.0));
        let mut home = Matrix4::identity();
        home[(0, 3)] = g.l1 + g.l3;
        home[(1, 3)] = g.l2 - g.d20;
        product_of_exponentials(&[xi1, xi2], &[q.theta1, q.d2], &home) // [RS eq. 1]
    }

    /// [RS eqs. 7–8]: joint values putting the tip at `p`, or `None` when `p` is
    /// closer to O than l₃ (no handle extension reaches it). The returned d₂
    /// may be negative or beyond the stroke; limits are the planner's business.
    #[inline]
    pub fn inverse(&self, p: [f64; 2]) -> Option<Joints> {
        let g = &self.geometry;
        // [RS eq. 4]–[RS eq. 5]: p is b, the translation of the tip pose
        // T = [a b; 0 1]; comparing it with [RS eq. 3] gives [RS eq. 6].
        let (dx, dy) = (p[0] - g.l1, p[1] - g.l2);
        let dd = dx * dx + dy * dy - g.l3 * g.l3;
        if dd.is_nan() || dd <= 0.0 {
            return None;
        }
        let d = dd.sqrt(); // [RS eq. 8]: D = d₂ + d₂₀
        let theta1 = (dy * g.l3 + dx * d).atan2(dx * g.l3 - dy * d); // [RS eq. 7]
        Some(Joints {
            theta1,
            d2: d - g.d20,
        })
    }

    /// Joint state from the tip's position, velocity and acceleration
    /// (inverse of the rate relations in the module docs). sin θ₁ and cos θ₁
    /// come from [RS eq. 7]'s numerator and denominator over l₃² + D², so no
    /// trigonometric call is made but the atan2 for θ₁ itself.
    #[inline]
    pub fn joint_state(&self, p: [f64; 2], v: [f64; 2], a: [f64; 2]) -> Option<JointState> {
        let g = &self.geometry;
        let (dx, dy) = (p[0] - g.l1, p[1] - g.l2);
        let r2 = dx * dx + dy * dy;
        let dd = r2 - g.l3 * g.l3;
        if dd.is_nan() || dd <= 0.0 {
            return None;
        }
        let d = dd.sqrt();
        let (num, den) = (dy * g.l3 + dx * d, dx * g.l3 - dy * d); // [RS eq. 7]
        let (sn, cs) = (num / r2, den / r2);
        let (u, n) = ([sn, -cs], [cs, sn]);
        let (vn, vu) = (v[0] * n[0] + v[1] * n[1], v[0] * u[0] + v[1] * u[1]);
        let (an, au) = (a[0] * n[0] + a[1] * n[1], a[0] * u[0] + a[1] * u[1]);
        let theta1_dot = vn / d;
        let d2_dot = vu + g.l3 * theta1_dot;
        let theta1_ddot = (an - 2.0 * theta1_dot * d2_dot + g.l3 * theta1_dot * theta1_dot) / d;
        let d2_ddot = au + g.l3 * theta1_ddot + d * theta1_dot * theta1_dot;
        Some(JointState {
            q: Joints {
                theta1: num.atan2(den),
                d2: d - g.d20,
            },
            theta1_dot,
            d2_dot,
            theta1_ddot,
            d2_ddot,
            u,
            n,
        })
    }

    /// The bail pin C, on the handle axis `bail_behind_tip` behind the tip's foot.
    #[inline]
    pub fn bail(&self, q: Joints) -> [f64; 2] {
        self.bail_at(handle_axes(q.theta1).0, q.d2)
    }

    /// [`RopeShovel::bail`] for a known handle direction u.
    #[inline]
    pub fn bail_at(&self, u: [f64; 2], d2: f64) -> [f64; 2] {
        let g = &self.geometry;
        let s = d2 + g.d20 - g.bail_behind_tip;
        [g.l1 + s * u[0], g.l2 + s * u[1]]
    }

    /// The hoist rope at C: the unit vector from C along the rope to where it
    /// leaves the boom point sheave (the tangent on the sheave's front, the
    /// side away from the machine), and the free rope length. `None` when C
    /// is inside the sheave.
    #[inline]
    pub fn rope(&self, c: [f64; 2]) -> Option<([f64; 2], f64)> {
        let g = &self.geometry;
        let (wx, wy) = (g.sheave[0] - c[0], g.sheave[1] - c[1]);
        let dist = (wx * wx + wy * wy).sqrt();
        let r = g.sheave_radius;
        if dist.is_nan() || dist <= r {
            return None;
        }
        let tangent = (dist * dist - r * r).sqrt();
        // Rotate C→B clockwise by asin(r / dist): the front tangent.
        let (s, co) = (r / dist, tangent / dist);
        let (ux, uy) = (wx / dist, wy / dist);
        Some(([ux * co + uy * s, -ux * s + uy * co], tangent))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::MachineProfile;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn shovel() -> RopeShovel {
        RopeShovel::new(MachineProfile::scale_model().geometry())
    }

    #[test]
    fn poe_product_equals_the_closed_form_of_eq_3() {
        let s = shovel();
        for &(theta1, d2) in &[(0.0, 0.0), (-0.1, 0.02), (0.7, 0.15), (1.4, 0.2)] {
            let q = Joints { theta1, d2 };
            let t = s.forward_poe(q);
            let p = s.forward(q);
            assert_relative_eq!(t[(0, 3)], p[0], epsilon = 1e-14);
            assert_relative_eq!(t[(1, 3)], p[1], epsilon = 1e-14);
            // Rotation part of [RS eq. 3]: rot_z(θ₁).
            assert_relative_eq!(t[(0, 0)], theta1.cos(), epsilon = 1e-14);
            assert_relative_eq!(t[(1, 0)], theta1.sin(), epsilon = 1e-14);
        }
    }

    #[test]
    fn the_default_start_pose_puts_the_retracted_tip_on_the_toe() {
        let s = RopeShovel::new(crate::profile::tests::retracted_start().geometry());
        let q = s.inverse([0.0, 0.0]).unwrap();
        assert_relative_eq!(q.d2, 0.0, epsilon = 1e-12);
        assert_relative_eq!(q.theta1.to_degrees(), -5.6, epsilon = 0.1);
    }

    proptest! {
        #[test]
        fn inverse_undoes_forward_over_the_workspace(
            theta1 in -0.6f64..1.55, d2 in -0.1f64..0.25
        ) {
            let s = shovel();
            let q = Joints { theta1, d2 };
            let back = s.inverse(s.forward(q)).unwrap();
            prop_assert!((back.theta1 - theta1).abs() < 1e-9);
            prop_assert!((back.d2 - d2).abs() < 1e-9);
        }

        #[test]
        fn joint_rates_match_finite_differences(
            theta1 in -0.3f64..1.4, d2 in 0.0f64..0.2,
            w in -0.2f64..0.2, v in -0.05f64..0.05, al in -0.05f64..0.05, ac in -0.02f64..0.02
        ) {
            // Move the joints on a known quadratic and compare the recovered
            // rates with the ones we put in.
            let s = shovel();
            let h = 1e-4;
            let at = |t: f64| s.forward(Joints { theta1: theta1 + w * t + 0.5 * al * t * t, d2: d2 + v * t + 0.5 * ac * t * t });
            let (pm, p0, pp) = (at(-h), at(0.0), at(h));
            let vel = [(pp[0] - pm[0]) / (2.0 * h), (pp[1] - pm[1]) / (2.0 * h)];
            let acc = [(pp[0] - 2.0 * p0[0] + pm[0]) / (h * h), (pp[1] - 2.0 * p0[1] + pm[1]) / (h * h)];
            let st = s.joint_state(p0, vel, acc).unwrap();
            prop_assert!((st.theta1_dot - w).abs() < 1e-6);
            prop_assert!((st.d2_dot - v).abs() < 1e-6);
            prop_assert!((st.theta1_ddot - al).abs() < 1e-3);
            prop_assert!((st.d2_ddot - ac).abs() < 1e-3);
        }
    }

    #[test]
    fn the_rope_is_tangent_to_the_sheave() {
        let s = shovel();
        let c = s.bail(Joints {
            theta1: 0.3,
            d2: 0.05,
        });
        let (e, len) = s.rope(c).unwrap();
        let t = [c[0] + e[0] * len, c[1] + e[1] * len];
        let b = s.geometry.sheave;
        let r = (t[0] - b[0]).hypot(t[1] - b[1]);
        assert_relative_eq!(r, s.geometry.sheave_radius, epsilon = 1e-12);
        // Radius ⟂ rope at the tangent point, on the side away from the machine.
        assert_relative_eq!(
            (t[0] - b[0]) * e[0] + (t[1] - b[1]) * e[1],
            0.0,
            epsilon = 1e-12
        );
        assert!(t[0] > b[0] - 1e-9);
    }
}
