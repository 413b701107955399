//! The tooth-tip trajectory of [RS eqs. 22–24]: two 6th-order polynomials in time
//! from the toe (0, 0) to (g_x, g_y) in t_d seconds, at rest with zero
//! acceleration at both ends ([RS eq. 23]).
//!
//! [RS eq. 23] fixes a₀ = a₁ = a₂ = 0 and three of a₃…a₆; what remains is the
//! decision vector x = [a_x6, a_y6, t_d, g_x, g_y]. The printed [RS eq. 24] is
//! garbled; its content (SPEC §4.3) is, per axis,
//!
//! ```text
//!     g(t) = g·(10τ³ − 15τ⁴ + 6τ⁵) + a₆·t³(t − t_d)³,   τ = t / t_d
//!     a₃ = 10g/t_d³ − a₆t_d³,  a₄ = −15g/t_d⁴ + 3a₆t_d²,  a₅ = 6g/t_d⁵ − 3a₆t_d
//! ```
//!
//! The first term is the minimum-jerk straight line; a₆ bends the path by
//! −a₆(t_d/2)⁶ at mid-dig (a few centimetres for Table 4's values).

/// The decision vector of [RS eq. 24].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Decision {
    /// a_x6 (m/s⁶).
    pub ax6: f64,
    /// a_y6 (m/s⁶).
    pub ay6: f64,
    /// t_d: dig time (s).
    pub td_s: f64,
    /// g_x: final tip x (m).
    pub gx_m: f64,
    /// g_y: final tip y (m).
    pub gy_m: f64,
}

impl Decision {
    /// From the optimiser's vector [a_x6, a_y6, t_d, g_x, g_y].
    pub fn from_slice(x: &[f64]) -> Self {
        Self {
            ax6: x[0],
            ay6: x[1],
            td_s: x[2],
            gx_m: x[3],
            gy_m: x[4],
        }
    }

    /// As the optimiser's vector.
    pub fn to_vec(self) -> Vec<f64> {
        vec![self.ax6, self.ay6, self.td_s, self.gx_m, self.gy_m]
    }

    /// From mid-dig bends instead of a₆: the a₆ term moves the tip by
    /// −a₆(t_d/2)⁶ at t_d/2, so a₆ = −bend / (t_d/2)⁶. The planner searches
    /// in [bend_x, bend_y, t_d, g_x, g_y], where a change of t_d alone keeps
    /// the path's shape; in the paper's coordinates the same path needs a₆
    /// and t_d moved together along a narrow valley (a₆ ∝ t_d⁻⁶).
    pub fn from_bends(bend_x_m: f64, bend_y_m: f64, td_s: f64, gx_m: f64, gy_m: f64) -> Self {
        let k = (0.5 * td_s).powi(6);
        Self {
            ax6: -bend_x_m / k,
            ay6: -bend_y_m / k,
            td_s,
            gx_m,
            gy_m,
        }
    }

    /// Mid-dig bends [x, y] of the a₆ terms (m) (see [`Decision::from_bends`]).
    pub fn bends(&self) -> [f64; 2] {
        let k = (0.5 * self.td_s).powi(6);
        [-self.ax6 * k, -self.ay6 * k]
    }

    /// The two polynomials.
    pub fn trajectory(&self) -> Trajectory {
        Trajectory {
            x: Sextic::rest_to_rest(self.gx_m, self.ax6, self.td_s),
            y: Sextic::rest_to_rest(self.gy_m, self.ay6, self.td_s),
            td_s: self.td_s,
        }
    }
}

/// One axis of [RS eq. 22]: g(t) = Σ aᵢ tⁱ, i = 0…6.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Sextic {
    /// a₀ … a₆.
    pub coefficients: [f64; 7],
}

impl Sextic {
    /// [RS eq. 24]: from 0 to `end` in `td` seconds, at rest at both ends, with
    /// the free coefficient a₆.
    pub fn rest_to_rest(end: f64, a6: f64, td: f64) -> Self {
        let (t2, t3) = (td * td, td * td * td);
        let (t4, t5) = (t2 * t2, t2 * t3);
        Self {
            // a₀ = a₁ = a₂ = 0 and the three below: at rest at both ends ([RS eq. 23]).
            coefficients: [
                0.0,
                0.0,
                0.0,
                10.0 * end / t3 - a6 * t3, // [RS eq. 24]
                -15.0 * end / t4 + 3.0 * a6 * t2,
                6.0 * end / t5 - 3.0 * a6 * td,
                a6,
            ],
        }
    }

    /// Position, velocity and acceleration at time t (Horner).
    #[inline]
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let a = &self.coefficients;
        // [RS eq. 22] and its derivatives.
        let p = ((((((a[6] * t + a[5]) * t + a[4]) * t + a[3]) * t + a[2]) * t + a[1]) * t) + a[0];
        let v = (((((6.0 * a[6] * t + 5.0 * a[5]) * t + 4.0 * a[4]) * t + 3.0 * a[3]) * t
            + 2.0 * a[2])
            * t)
            + a[1];
        let acc = ((((30.0 * a[6] * t + 20.0 * a[5]) * t + 12.0 * a[4]) * t + 6.0 * a[3]) * t)
            + 2.0 * a[2];
        [p, v, acc]
    }
}

/// The tip trajectory of [RS eq. 22].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Trajectory {
    /// g_x(t).
    pub x: Sextic,
    /// g_y(t).
    pub y: Sextic,
    /// t_d (s).
    pub td_s: f64,
}

/// Tip position, velocity and acceleration at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipState {
    /// Time (s).
    pub t: f64,
    /// Position (m).
    pub p: [f64; 2],
    /// Velocity (m/s).
    pub v: [f64; 2],
    /// Acceleration (m/s²).
    pub a: [f64; 2],
}

impl Trajectory {
    /// The tip at time t ([RS eq. 22]).
    #[inline]
    pub fn at(&self, t: f64) -> TipState {
        let [x, vx, ax] = self.x.eval(t);
        let [y, vy, ay] = self.y.eval(t);
        TipState {
            t,
            p: [x, y],
            v: [vx, vy],
            a: [ax, ay],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn eq_23_boundary_conditions_hold_for_any_a6() {
        for &a6 in &[-2e-6, 0.0, 1.1e-6] {
            let s = Sextic::rest_to_rest(0.35, a6, 11.85);
            let [p0, v0, a0] = s.eval(0.0);
            let [p1, v1, a1] = s.eval(11.85);
            assert_relative_eq!(p0, 0.0);
            assert_relative_eq!(v0, 0.0);
            assert_relative_eq!(a0, 0.0);
            assert_relative_eq!(p1, 0.35, epsilon = 1e-12);
            assert_relative_eq!(v1, 0.0, epsilon = 1e-12);
            assert_relative_eq!(a1, 0.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn a6_bends_the_path_by_the_closed_form_at_mid_dig() {
        let (g, td, a6) = (0.3489, 11.85, -9.98e-7);
        let bent = Sextic::rest_to_rest(g, a6, td).eval(td / 2.0)[0];
        let straight = Sextic::rest_to_rest(g, 0.0, td).eval(td / 2.0)[0];
        assert_relative_eq!(straight, g / 2.0, epsilon = 1e-12);
        assert_relative_eq!(bent - straight, -a6 * (td / 2.0).powi(6), epsilon = 1e-12);
        // Table 4's typical a_x6 pushes the tip 4.3 cm further into the pile.
        assert_relative_eq!(bent - straight, 0.0432, epsilon = 1e-3);
    }

    #[test]
    fn bends_round_trip_to_a6() {
        let d = Decision::from_bends(0.0432, -0.0234, 11.85, 0.3489, 0.3159);
        assert_relative_eq!(d.ax6, -9.98e-7, max_relative = 2e-3);
        assert_relative_eq!(d.ay6, 5.41e-7, max_relative = 2e-3);
        assert_relative_eq!(d.bends()[0], 0.0432, epsilon = 1e-15);
        assert_relative_eq!(d.bends()[1], -0.0234, epsilon = 1e-15);
    }

    #[test]
    fn velocity_and_acceleration_are_the_derivatives() {
        let s = Sextic::rest_to_rest(0.3, 7e-7, 10.0);
        let h = 1e-5;
        for &t in &[1.0, 4.2, 9.3] {
            let [_, v, a] = s.eval(t);
            let fd_v = (s.eval(t + h)[0] - s.eval(t - h)[0]) / (2.0 * h);
            let fd_a = (s.eval(t + h)[1] - s.eval(t - h)[1]) / (2.0 * h);
            assert_relative_eq!(v, fd_v, epsilon = 1e-8);
            assert_relative_eq!(a, fd_a, epsilon = 1e-8);
        }
    }
}
