//! Product-of-exponentials (PoE) kinematics: unit twists and their matrix
//! exponentials ([RS eq. 1]–[RS eq. 2]; Murray, Li & Sastry 1994, §2.3).
//!
//! A joint is a unit twist ξ = (ω, v) in the base frame at the home
//! configuration. For a revolute joint ω is the unit axis and v = r × ω for any
//! point r on the axis (the paper's ν = r × ω); for a prismatic joint ω = 0 and
//! v is the unit direction of travel. The pose of the end frame is
//!
//! ```text
//!     T(q) = e^{[ξ₁]q₁} e^{[ξ₂]q₂} ⋯ e^{[ξₙ]qₙ} T(0)          ([RS eq. 1])
//! ```
//!
//! and each factor is [RS eq. 2]:
//!
//! ```text
//!     e^{[ξ]θ} = [ e^{[ω]θ}   (I − e^{[ω]θ})(ω × v) + ω ωᵀ v θ ]   (ω ≠ 0)
//!                [ 0          1                                 ]
//!     e^{[ξ]θ} = [ I  v θ ; 0  1 ]                                 (ω = 0)
//! ```
//!
//! with Rodrigues' formula e^{\[ω\]θ} = I + sin θ \[ω\] + (1 − cos θ)\[ω\]².
//! Written here rather than taken from a robotics crate because the two
//! closed forms are a dozen lines on nalgebra, and the kinematics crates on
//! crates.io (k, urdf-rs) model URDF chains, not bare twists.

use nalgebra::{Matrix3, Matrix4, Vector3};

/// A unit twist ξ = (ω, v) of one joint, in the base frame at home.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    /// Angular part ω: the unit axis of a revolute joint, zero for a prismatic one.
    pub omega: Vector3<f64>,
    /// Linear part v: r × ω for a revolute joint, the unit direction for a prismatic one.
    pub v: Vector3<f64>,
}

impl Twist {
    /// Revolute joint about the unit `axis` through `point` (v = r × ω).
    pub fn revolute(axis: Vector3<f64>, point: Vector3<f64>) -> Self {
        let omega = axis.normalize();
        Self {
            omega,
            v: point.cross(&omega),
        }
    }

    /// Prismatic joint along `direction` (normalised).
    pub fn prismatic(direction: Vector3<f64>) -> Self {
        Self {
            omega: Vector3::zeros(),
            v: direction.normalize(),
        }
    }

    /// The matrix exponential e^{\[ξ\]θ} of [RS eq. 2] (θ in rad for a revolute
    /// joint, m for a prismatic one).
    pub fn exp(&self, theta: f64) -> Matrix4<f64> {
        // [RS eq. 2]: prismatic (ω = 0) then revolute by Rodrigues.
        let mut t = Matrix4::identity();
        if self.omega.norm_squared() == 0.0 {
            t.fixed_view_mut::<3, 1>(0, 3).copy_from(&(self.v * theta));
            return t;
        }
        let w = self.omega;
        let rot = rodrigues(&w, theta);
        let p = (Matrix3::identity() - rot) * w.cross(&self.v) + w * w.dot(&self.v) * theta;
        t.fixed_view_mut::<3, 3>(0, 0).copy_from(&rot);
        t.fixed_view_mut::<3, 1>(0, 3).copy_from(&p);
        t
    }
}

/// Rodrigues' formula e^{\[ω\]θ} for a unit axis ω.
pub fn rodrigues(omega: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let k = omega.cross_matrix();
    Matrix3::identity() + k * theta.sin() + k * k * (1.0 - theta.cos())
}

/// Eq. 1: T(q) = Π e^{\[ξᵢ\]qᵢ} · T(0). `twists` and `q` pair up joint by joint.
///
/// ```
/// use autoshovel_core::poe::{product_of_exponentials, Twist};
/// use nalgebra::{Matrix4, Vector3};
/// // One revolute joint about z through the origin, tool 1 m out on x.
/// let joint = Twist::revolute(Vector3::z(), Vector3::zeros());
/// let mut home = Matrix4::identity();
/// home[(0, 3)] = 1.0;
/// let t = product_of_exponentials(&[joint], &[std::f64::consts::FRAC_PI_2], &home);
/// assert!((t[(0, 3)]).abs() < 1e-12 && (t[(1, 3)] - 1.0).abs() < 1e-12);
/// ```
pub fn product_of_exponentials(twists: &[Twist], q: &[f64], home: &Matrix4<f64>) -> Matrix4<f64> {
    assert_eq!(twists.len(), q.len(), "one joint value per twist");
    let mut t = Matrix4::identity();
    for (xi, &qi) in twists.iter().zip(q) {
        t *= xi.exp(qi);
    }
    // [RS eq. 1]: T(q) = e^{[ξ₁]q₁} ⋯ e^{[ξₙ]qₙ} T(0).
    t * home
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn revolute_exponential_rotates_points_about_its_axis() {
        // Axis z through (1, 2, 0): the point (2, 2, 0) turns a quarter to (1, 3, 0).
        let xi = Twist::revolute(Vector3::z(), Vector3::new(1.0, 2.0, 0.0));
        let t = xi.exp(std::f64::consts::FRAC_PI_2);
        let p = t * nalgebra::Vector4::new(2.0, 2.0, 0.0, 1.0);
        assert_relative_eq!(p.x, 1.0, epsilon = 1e-12);
        assert_relative_eq!(p.y, 3.0, epsilon = 1e-12);
        // The axis point itself does not move.
        let o = t * nalgebra::Vector4::new(1.0, 2.0, 5.0, 1.0);
        assert_relative_eq!(o.x, 1.0, epsilon = 1e-12);
        assert_relative_eq!(o.y, 2.0, epsilon = 1e-12);
        assert_relative_eq!(o.z, 5.0, epsilon = 1e-12);
    }

    #[test]
    fn exponential_is_a_one_parameter_group() {
        // e^{ξa} e^{ξb} = e^{ξ(a+b)} for a screw with pitch (ω·v ≠ 0).
        let xi = Twist {
            omega: Vector3::new(1.0, 2.0, 2.0) / 3.0,
            v: Vector3::new(0.3, -0.1, 0.7),
        };
        let lhs = xi.exp(0.4) * xi.exp(1.1);
        let rhs = xi.exp(1.5);
        assert_relative_eq!(lhs, rhs, epsilon = 1e-12);
        assert_relative_eq!(xi.exp(0.0), Matrix4::identity(), epsilon = 1e-15);
        // Prismatic: pure translation.
        let slide = Twist::prismatic(Vector3::new(0.0, -2.0, 0.0));
        assert_relative_eq!(slide.exp(0.25)[(1, 3)], -0.25, epsilon = 1e-15);
    }

    #[test]
    fn rodrigues_is_a_rotation() {
        let w = Vector3::new(0.2, -0.5, 0.9).normalize();
        let r = rodrigues(&w, 0.77);
        assert_relative_eq!(r * r.transpose(), Matrix3::identity(), epsilon = 1e-12);
        assert_relative_eq!(r.determinant(), 1.0, epsilon = 1e-12);
        assert_relative_eq!(r * w, w, epsilon = 1e-12);
    }
}
