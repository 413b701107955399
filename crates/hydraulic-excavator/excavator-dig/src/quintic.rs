//! Quintic joint paths ([HE eq. 1]): θ(t) = a₀ + a₁t + a₂t² + a₃t³ + a₄t⁴ + a₅t⁵
//! with the joint angle, velocity and acceleration given at both ends.
//!
//! The planner uses zero velocity and acceleration at both ends, for which
//! the coefficients reduce to θ(t) = θ₀ + (θ₁ − θ₀)·s(τ), τ = t/T,
//! s(τ) = 10τ³ − 15τ⁴ + 6τ⁵. Every joint then follows the same blend s, so a
//! segment is a straight line in joint space between two inverse-kinematics
//! solutions and the tooth tip, their forward image, runs on a **curved**
//! path (not the straight line between the end points). Since s is monotone,
//! each joint and the attitude angle φ = Σθ stay between their end values.
//! The peak rate is max ṡ = 15/8 at τ = ½, so |θ̇| ≤ (15/8)|θ₁ − θ₀|/T.

use crate::kinematics::Joints;

/// Peak of ds/dτ for the zero-boundary blend.
pub const PEAK_RATE: f64 = 15.0 / 8.0;

/// One scalar quintic ([HE eq. 1]) over [0, T].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quintic {
    /// a₀ … a₅.
    pub coeffs: [f64; 6],
    /// T (s).
    pub duration_s: f64,
}

impl Quintic {
    /// The quintic of [HE eq. 1] with θ, θ̇, θ̈ = `start` at t = 0 and `end` at t = T.
    pub fn new(start: [f64; 3], end: [f64; 3], duration_s: f64) -> Self {
        let t = duration_s;
        let [p0, v0, a0] = start;
        let [p1, v1, a1] = end;
        let (t2, t3, t4, t5) = (t * t, t * t * t, t.powi(4), t.powi(5));
        let h = p1 - p0;
        let a3 = (20.0 * h - (8.0 * v1 + 12.0 * v0) * t - (3.0 * a0 - a1) * t2) / (2.0 * t3);
        let a4 =
            (-30.0 * h + (14.0 * v1 + 16.0 * v0) * t + (3.0 * a0 - 2.0 * a1) * t2) / (2.0 * t4);
        let a5 = (12.0 * h - 6.0 * (v1 + v0) * t - (a0 - a1) * t2) / (2.0 * t5);
        Self {
            // a₀ … a₅ of [HE eq. 1] from the six boundary conditions.
            coeffs: [p0, v0, 0.5 * a0, a3, a4, a5],
            duration_s,
        }
    }

    /// θ, θ̇, θ̈ at time t: [HE eq. 1] and its first two derivatives.
    pub fn eval(&self, t: f64) -> [f64; 3] {
        let a = &self.coeffs;
        let p = a[0] + t * (a[1] + t * (a[2] + t * (a[3] + t * (a[4] + t * a[5])))); // [HE eq. 1]
        let v = a[1] + t * (2.0 * a[2] + t * (3.0 * a[3] + t * (4.0 * a[4] + t * 5.0 * a[5])));
        let acc = 2.0 * a[2] + t * (6.0 * a[3] + t * (12.0 * a[4] + t * 20.0 * a[5]));
        [p, v, acc]
    }
}

/// The zero-boundary blend s(τ), ds/dτ, d²s/dτ² for τ ∈ [0, 1] (clamped):
/// [HE eq. 1] at rest at both ends, normalised.
#[inline]
pub fn blend(tau: f64) -> [f64; 3] {
    let t = tau.clamp(0.0, 1.0);
    let t2 = t * t;
    [
        t2 * t * (10.0 + t * (-15.0 + 6.0 * t)), // [HE eq. 1]: s = 10τ³ − 15τ⁴ + 6τ⁵
        30.0 * t2 * (1.0 - t) * (1.0 - t),
        60.0 * t * (1.0 - t) * (1.0 - 2.0 * t),
    ]
}

/// A quintic in joint space from `q0` to `q1` over `duration_s`, at rest at both ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointQuintic {
    /// Start joints (rad).
    pub q0: Joints,
    /// End joints (rad).
    pub q1: Joints,
    /// T (s).
    pub duration_s: f64,
}

impl JointQuintic {
    /// Joints at the path parameter σ = s(τ) ∈ [0, 1] (the geometry, without timing).
    #[inline]
    pub fn at_fraction(&self, sigma: f64) -> Joints {
        self.q0 + (self.q1 - self.q0) * sigma
    }

    /// (q, q̇, q̈) at time t ∈ [0, T]: [HE eq. 1] per joint, at rest at both ends.
    #[inline]
    pub fn state(&self, t: f64) -> (Joints, Joints, Joints) {
        let [s, ds, dds] = blend(t / self.duration_s);
        let dq = self.q1 - self.q0;
        let t_inv = 1.0 / self.duration_s;
        (
            self.q0 + dq * s, // [HE eq. 1]
            dq * (ds * t_inv),
            dq * (dds * t_inv * t_inv),
        )
    }

    /// The shortest duration that keeps every joint at or below `fraction` of its
    /// speed limit, and at least `min_s`.
    pub fn duration_for(
        q0: &Joints,
        q1: &Joints,
        speed_rad_s: &[f64; 3],
        fraction: f64,
        min_s: f64,
    ) -> f64 {
        (0..3)
            .map(|i| PEAK_RATE * (q1[i] - q0[i]).abs() / (fraction * speed_rad_s[i]))
            .fold(min_s, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn the_general_quintic_meets_all_six_boundary_conditions() {
        let (start, end, t) = ([0.3, -0.2, 0.5], [-1.1, 0.4, -0.3], 2.7);
        let q = Quintic::new(start, end, t);
        let a = q.eval(0.0);
        let b = q.eval(t);
        for i in 0..3 {
            assert_relative_eq!(a[i], start[i], epsilon = 1e-12);
            assert_relative_eq!(b[i], end[i], epsilon = 1e-10);
        }
    }

    #[test]
    fn the_zero_boundary_quintic_is_the_blend() {
        let q = Quintic::new([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 1.0);
        for k in 0..=10 {
            let tau = k as f64 / 10.0;
            let [p, v, a] = q.eval(tau);
            let [s, ds, dds] = blend(tau);
            assert_relative_eq!(p, s, epsilon = 1e-12);
            assert_relative_eq!(v, ds, epsilon = 1e-12);
            assert_relative_eq!(a, dds, epsilon = 1e-11);
        }
        assert_relative_eq!(blend(0.5)[1], PEAK_RATE, epsilon = 1e-15);
    }

    #[test]
    fn a_joint_segment_starts_and_ends_at_rest_and_respects_its_speed() {
        let q0 = Joints::new(0.4, -1.2, 0.3);
        let q1 = Joints::new(0.1, -1.9, -1.4);
        let speed = [0.5, 0.7, 1.0];
        let t = JointQuintic::duration_for(&q0, &q1, &speed, 0.8, 0.5);
        let seg = JointQuintic {
            q0,
            q1,
            duration_s: t,
        };
        let (a, va, aa) = seg.state(0.0);
        let (b, vb, ab) = seg.state(t);
        assert_relative_eq!(a, q0, epsilon = 1e-15);
        assert_relative_eq!(b, q1, epsilon = 1e-12);
        for v in [va, vb, aa, ab] {
            assert_relative_eq!(v.norm(), 0.0, epsilon = 1e-12);
        }
        let mut peak = [0.0f64; 3];
        for k in 0..=1000 {
            let (_, v, _) = seg.state(t * k as f64 / 1000.0);
            for i in 0..3 {
                peak[i] = peak[i].max(v[i].abs() / speed[i]);
            }
        }
        assert!(peak.iter().all(|&p| p <= 0.8 + 1e-9), "{peak:?}");
        assert!(peak.iter().any(|&p| p > 0.8 - 1e-6), "{peak:?}");
    }
}
