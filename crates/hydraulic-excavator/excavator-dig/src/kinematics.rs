//! Backhoe kinematics by Denavit–Hartenberg (paper §1.1): boom, stick and
//! bucket as a planar 3R chain, forward to the tooth tip and back with a
//! digging attitude angle.
//!
//! # Frames and the D-H table
//! The dig plane (SPEC §1): x horizontal away from the machine, origin on the
//! slew axis at ground level, y up; z out of the plane, so every joint axis is
//! z and counter-clockwise angles are positive. The base frame {0} sits at the
//! boom foot pin (`boom_foot_x_m`, `boom_foot_height_m`) with the world's axes.
//! Standard D-H, ⁱ⁻¹Tᵢ = Rot_z(θᵢ) Trans_z(dᵢ) Trans_x(aᵢ) Rot_x(αᵢ):
//!
//! | i | joint | θᵢ | dᵢ | aᵢ | αᵢ |
//! |---|---|---|---|---|---|
//! | 1 | boom foot | θ₁ (boom from the horizontal) | 0 | a₁ = 4.6 m | 0 |
//! | 2 | stick pin | θ₂ (stick relative to the boom) | 0 | a₂ = 2.5 m | 0 |
//! | 3 | bucket pin | θ₃ (bucket link relative to the stick) | 0 | a₃ = 1.2 m | 0 |
//!
//! so `world_from_tip = world_from_base · ⁰T₁ · ¹T₂ · ²T₃`, the tip is its
//! translation, and the **digging attitude angle** is the absolute angle of
//! the bucket link (bucket pin → tooth tip) from +x, φ = θ₁ + θ₂ + θ₃, taken
//! unwrapped (−90° points straight down, −180° towards the machine, −210°
//! towards the machine and 30° up, as at the end of a dig). The paper
//! (refs. 12, 14) asks that it stay in a range; the profile gives the range.
//!
//! # Inverse
//! Given the tip p and φ, the bucket pin is w = p − a₃(cos φ, sin φ); the
//! boom and stick are a 2-link problem for w: cos θ₂ = (|w − o|² − a₁² − a₂²)/(2a₁a₂)
//! on the branch θ₂ < 0 (the stick folds below the boom, the only branch a
//! backhoe's cylinders allow), θ₁ = atan2(w − o) − atan2(a₂ sin θ₂, a₁ + a₂ cos θ₂),
//! θ₃ = φ − θ₁ − θ₂.

use std::fmt;

use autoshovel_core::Vec2;
use nalgebra::{Matrix2x3, Matrix4, Vector3};
use serde::Serialize;

use crate::profile::MachineProfile;

/// Joint angles [θ₁ boom, θ₂ stick, θ₃ bucket] (rad).
pub type Joints = Vector3<f64>;

/// One of the three joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Joint {
    /// θ₁, boom foot.
    Boom,
    /// θ₂, stick pin.
    Stick,
    /// θ₃, bucket pin.
    Bucket,
}

impl Joint {
    /// The three joints in chain order.
    pub const ALL: [Joint; 3] = [Joint::Boom, Joint::Stick, Joint::Bucket];

    /// Index into [`Joints`].
    pub fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for Joint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Joint::Boom => "boom (θ1)",
            Joint::Stick => "stick (θ2)",
            Joint::Bucket => "bucket (θ3)",
        })
    }
}

/// Why the inverse kinematics refused a tooth-tip pose.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IkError {
    /// The stick pin (tip minus the bucket link at the attitude angle) is
    /// farther from the boom foot than boom + stick, or nearer than their difference.
    #[error(
        "out of reach: the stick-pin point is {distance_m:.3} m from the boom foot, \
         the boom and stick reach {min_m:.3}..{max_m:.3} m"
    )]
    OutOfReach {
        /// Distance from the boom foot to the stick pin the pose needs (m).
        distance_m: f64,
        /// Least distance boom and stick can make (m).
        min_m: f64,
        /// Greatest distance (m).
        max_m: f64,
    },
    /// A joint would leave its range.
    #[error(
        "{joint} joint at {:.2}° is outside its range {:.1}°..{:.1}°",
        value_rad.to_degrees(), min_rad.to_degrees(), max_rad.to_degrees()
    )]
    JointOutOfLimit {
        /// The joint.
        joint: Joint,
        /// The angle the pose needs (rad).
        value_rad: f64,
        /// Lower limit (rad).
        min_rad: f64,
        /// Upper limit (rad).
        max_rad: f64,
    },
    /// The digging attitude angle is outside its range.
    #[error(
        "attitude angle {:.2}° is outside its range {:.1}°..{:.1}°",
        value_rad.to_degrees(), min_rad.to_degrees(), max_rad.to_degrees()
    )]
    AttitudeOutOfRange {
        /// The attitude angle φ = θ₁ + θ₂ + θ₃ (rad).
        value_rad: f64,
        /// Lower limit (rad).
        min_rad: f64,
        /// Upper limit (rad).
        max_rad: f64,
    },
}

/// One row of a D-H table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DhLink {
    /// aᵢ: link length along xᵢ (m).
    pub a_m: f64,
    /// αᵢ: link twist about xᵢ (rad).
    pub alpha_rad: f64,
    /// dᵢ: offset along zᵢ₋₁ (m).
    pub d_m: f64,
}

impl DhLink {
    /// ⁱ⁻¹Tᵢ(θ) = Rot_z(θ) Trans_z(d) Trans_x(a) Rot_x(α).
    pub fn transform(&self, theta_rad: f64) -> Matrix4<f64> {
        let (st, ct) = theta_rad.sin_cos();
        let (sa, ca) = self.alpha_rad.sin_cos();
        Matrix4::new(
            ct,
            -st * ca,
            st * sa,
            self.a_m * ct,
            st,
            ct * ca,
            -ct * sa,
            self.a_m * st,
            0.0,
            sa,
            ca,
            self.d_m,
            0.0,
            0.0,
            0.0,
            1.0,
        )
    }
}

/// The tooth tip: position and attitude angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipPose {
    /// Position in the dig plane (m).
    pub point: Vec2,
    /// φ = θ₁ + θ₂ + θ₃, unwrapped (rad).
    pub attitude_rad: f64,
}

/// Joint and attitude ranges (rad) and speed limits (rad/s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Limits {
    /// Lower joint limits.
    pub min_rad: [f64; 3],
    /// Upper joint limits.
    pub max_rad: [f64; 3],
    /// Attitude range [lower, upper].
    pub attitude_rad: [f64; 2],
    /// |q̇| limits.
    pub speed_rad_s: [f64; 3],
}

/// The boom–stick–bucket front of a backhoe.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Backhoe {
    /// D-H rows for boom, stick, bucket.
    pub dh: [DhLink; 3],
    /// Boom foot pin in the dig frame (m).
    pub boom_foot: [f64; 2],
    /// Ranges and speed limits.
    pub limits: Limits,
}

impl Backhoe {
    /// The front end of a profile.
    pub fn new(profile: &MachineProfile) -> Self {
        let g = &profile.geometry;
        let l = &profile.joint_limits;
        let s = &profile.speed_limits;
        let link = |a_m| DhLink {
            a_m,
            alpha_rad: 0.0,
            d_m: 0.0,
        };
        Self {
            dh: [
                link(g.boom_length_m),
                link(g.stick_length_m),
                link(g.bucket_tip_radius_m),
            ],
            boom_foot: [g.boom_foot_x_m, g.boom_foot_height_m],
            limits: Limits {
                min_rad: [
                    l.boom_min_deg.to_radians(),
                    l.stick_min_deg.to_radians(),
                    l.bucket_min_deg.to_radians(),
                ],
                max_rad: [
                    l.boom_max_deg.to_radians(),
                    l.stick_max_deg.to_radians(),
                    l.bucket_max_deg.to_radians(),
                ],
                attitude_rad: [
                    l.attitude_min_deg.to_radians(),
                    l.attitude_max_deg.to_radians(),
                ],
                speed_rad_s: [
                    s.boom_deg_s.to_radians(),
                    s.stick_deg_s.to_radians(),
                    s.bucket_deg_s.to_radians(),
                ],
            },
        }
    }

    /// Link lengths [a₁, a₂, a₃] (m).
    pub fn lengths(&self) -> [f64; 3] {
        [self.dh[0].a_m, self.dh[1].a_m, self.dh[2].a_m]
    }

    /// The boom foot pin as a vector.
    pub fn foot(&self) -> Vec2 {
        Vec2::new(self.boom_foot[0], self.boom_foot[1])
    }

    /// `world_from_base`: the base frame {0} at the boom foot.
    pub fn world_from_base(&self) -> Matrix4<f64> {
        let mut t = Matrix4::identity();
        t[(0, 3)] = self.boom_foot[0];
        t[(1, 3)] = self.boom_foot[1];
        t
    }

    /// The D-H frames `world_from_i` for i = 1, 2, 3 (stick pin, bucket pin, tip).
    pub fn dh_frames(&self, q: &Joints) -> [Matrix4<f64>; 3] {
        let world_from_1 = self.world_from_base() * self.dh[0].transform(q[0]);
        let world_from_2 = world_from_1 * self.dh[1].transform(q[1]);
        let world_from_3 = world_from_2 * self.dh[2].transform(q[2]);
        [world_from_1, world_from_2, world_from_3]
    }

    /// Forward kinematics by the D-H product (the definition; see
    /// [`Backhoe::forward`] for the fast closed form it equals).
    pub fn forward_dh(&self, q: &Joints) -> TipPose {
        let t = self.dh_frames(q)[2];
        TipPose {
            point: Vec2::new(t[(0, 3)], t[(1, 3)]),
            attitude_rad: q.sum(),
        }
    }

    /// Forward kinematics, closed form of the D-H product for α = d = 0.
    #[inline]
    pub fn forward(&self, q: &Joints) -> TipPose {
        let [_, _, tip] = self.joint_points(q);
        TipPose {
            point: tip,
            attitude_rad: q.sum(),
        }
    }

    /// Stick pin, bucket pin and tooth tip in the dig frame (m).
    #[inline]
    pub fn joint_points(&self, q: &Joints) -> [Vec2; 3] {
        let [a1, a2, a3] = self.lengths();
        let (s1, c1) = q[0].sin_cos();
        let (s12, c12) = (q[0] + q[1]).sin_cos();
        let (s123, c123) = (q[0] + q[1] + q[2]).sin_cos();
        let p1 = self.foot() + Vec2::new(a1 * c1, a1 * s1);
        let p2 = p1 + Vec2::new(a2 * c12, a2 * s12);
        let tip = p2 + Vec2::new(a3 * c123, a3 * s123);
        [p1, p2, tip]
    }

    /// Tip Jacobian ∂p/∂q (2 × 3): column i is the joint's axis z × (p − pᵢ).
    pub fn jacobian(&self, q: &Joints) -> Matrix2x3<f64> {
        let [p1, p2, tip] = self.joint_points(q);
        let foot = self.foot();
        let col = |o: Vec2| {
            let r = tip - o;
            Vec2::new(-r.y, r.x)
        };
        let (c0, c1, c2) = (col(foot), col(p1), col(p2));
        Matrix2x3::new(c0.x, c1.x, c2.x, c0.y, c1.y, c2.y)
    }

    /// Inverse kinematics of the tip `p` at attitude `attitude_rad`, without
    /// limit checks (module docs; branch θ₂ ≤ 0).
    #[inline]
    pub fn inverse_unchecked(&self, p: Vec2, attitude_rad: f64) -> Result<Joints, IkError> {
        let [a1, a2, a3] = self.lengths();
        let (sp, cp) = attitude_rad.sin_cos();
        let w = p - Vec2::new(a3 * cp, a3 * sp) - self.foot();
        let d2 = w.norm_squared();
        let (min, max) = ((a1 - a2).abs(), a1 + a2);
        let c2 = (d2 - a1 * a1 - a2 * a2) / (2.0 * a1 * a2);
        if !(-1.0..=1.0).contains(&c2) {
            return Err(IkError::OutOfReach {
                distance_m: d2.sqrt(),
                min_m: min,
                max_m: max,
            });
        }
        let s2 = -(1.0 - c2 * c2).sqrt();
        let th2 = s2.atan2(c2);
        let th1 = w.y.atan2(w.x) - (a2 * s2).atan2(a1 + a2 * c2);
        let th1 = autoshovel_core::wrap_angle(th1);
        Ok(Joints::new(th1, th2, attitude_rad - th1 - th2))
    }

    /// Inverse kinematics with the joint and attitude ranges checked.
    #[inline]
    pub fn inverse(&self, p: Vec2, attitude_rad: f64) -> Result<Joints, IkError> {
        self.check_attitude(attitude_rad)?;
        let q = self.inverse_unchecked(p, attitude_rad)?;
        self.check_joints(&q)?;
        Ok(q)
    }

    /// The first joint outside its range, if any.
    #[inline]
    pub fn check_joints(&self, q: &Joints) -> Result<(), IkError> {
        // A hair of tolerance so that a limit reached exactly by a plan passes.
        const TOL: f64 = 1e-9;
        for j in Joint::ALL {
            let i = j.index();
            let (lo, hi) = (self.limits.min_rad[i], self.limits.max_rad[i]);
            if !(q[i] >= lo - TOL && q[i] <= hi + TOL) {
                return Err(IkError::JointOutOfLimit {
                    joint: j,
                    value_rad: q[i],
                    min_rad: lo,
                    max_rad: hi,
                });
            }
        }
        Ok(())
    }

    /// The attitude range check.
    #[inline]
    pub fn check_attitude(&self, attitude_rad: f64) -> Result<(), IkError> {
        let [lo, hi] = self.limits.attitude_rad;
        if !(attitude_rad >= lo - 1e-9 && attitude_rad <= hi + 1e-9) {
            return Err(IkError::AttitudeOutOfRange {
                value_rad: attitude_rad,
                min_rad: lo,
                max_rad: hi,
            });
        }
        Ok(())
    }

    /// Joints and attitude checked together (for samples of a planned motion).
    #[inline]
    pub fn check(&self, q: &Joints) -> Result<(), IkError> {
        self.check_joints(q)?;
        self.check_attitude(q.sum())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn machine() -> Backhoe {
        Backhoe::new(&MachineProfile::excavator_15t())
    }

    #[test]
    fn straight_out_arm_reaches_the_sum_of_the_links() {
        let m = machine();
        let p = m.forward_dh(&Joints::zeros()).point;
        assert_relative_eq!(p.x, 0.15 + 4.6 + 2.5 + 1.2, epsilon = 1e-12);
        assert_relative_eq!(p.y, 1.7, epsilon = 1e-12);
    }

    #[test]
    fn the_jacobian_matches_finite_differences() {
        let m = machine();
        let q = Joints::new(0.3, -1.7, -1.0);
        let j = m.jacobian(&q);
        for i in 0..3 {
            let mut dq = Joints::zeros();
            dq[i] = 1e-6;
            let fd = (m.forward(&(q + dq)).point - m.forward(&(q - dq)).point) / 2e-6;
            assert_relative_eq!(j[(0, i)], fd.x, epsilon = 1e-7);
            assert_relative_eq!(j[(1, i)], fd.y, epsilon = 1e-7);
        }
    }

    #[test]
    fn ik_names_the_joint_or_the_reach_it_misses() {
        let m = machine();
        let far = m.inverse(Vec2::new(12.0, 0.0), -1.5).unwrap_err();
        assert!(matches!(far, IkError::OutOfReach { .. }), "{far}");
        assert!(far.to_string().contains("out of reach"), "{far}");
        // Straight down at the boom foot: the boom must drop below its limit.
        let low = m.inverse(Vec2::new(2.0, -4.0), -1.6).unwrap_err();
        assert!(matches!(low, IkError::JointOutOfLimit { .. }), "{low}");
        let att = m.inverse(Vec2::new(6.0, 0.0), 0.5).unwrap_err();
        assert!(matches!(att, IkError::AttitudeOutOfRange { .. }), "{att}");
    }
}
