//! Horizontal calibration of a point cloud (rope-shovel paper §3.1, [RS eq. 11]–[RS eq. 12]).
//!
//! The paper corrects a scan for the roll α and pitch β of the sensor with
//!
//! ```text
//!          ⎡ cos β          0       −sin β        ⎤
//!     T =  ⎢ sin α sin β    cos α    sin α cos β  ⎥        ([RS eq. 11])
//!          ⎣ cos α sin β   −sin α    cos α cos β  ⎦
//!
//!     p = T · p_s                                           ([RS eq. 12])
//! ```
//!
//! with `p_s` a raw (sensor) point and `p` the levelled one. This module applies
//! T exactly as printed; [`level`] is [RS eq. 12] and [`tilt`] its inverse `Tᵀ`.
//!
//! # How [RS eq. 11] reads
//! Multiplying out shows `T = Rx(−α) · Ry(−β)`, where `Rx`, `Ry` are the
//! right-handed elementary rotations about x and y. So:
//!
//! - **α turns about x**, **β turns about y**. In the paper's frame x lies
//!   across the crawler and y along it; in ours (SPEC §1, right-handed,
//!   z up) x points from the sensor towards the pile (the dig direction), y to
//!   the left. With x the look direction, α is a roll and β a pitch in the
//!   usual vehicle sense, which are the names the paper gives them.
//! - The sensor's axes, expressed in the level frame, are the columns of T:
//!   its x axis is `(cos β, sin α sin β, cos α sin β)`, its y axis
//!   `(0, cos α, −sin α)`. **β > 0 is nose up** (the sensor's x axis rises
//!   above the horizon by β); **α > 0 is left side down** (its y axis dips by α).
//!   Equivalently, the sensor attitude is `Ry(β)·Rx(α)` read as a rotation of
//!   the scene into sensor coordinates, i.e. a scan of level ground seen by a
//!   tilted sensor is `tilt(level_cloud, α, β)`.
//! - The floor normal `(0, 0, 1)` of the level frame appears in sensor
//!   coordinates as `n = Tᵀ e_z = (sin β cos α, −sin α, cos α cos β)`, the last
//!   row of T. [`angles_from_normal`] inverts this: `α = −asin n_y`,
//!   `β = atan2(n_x, n_z)`, unique for |α|, |β| < 90°.
//!
//! Rotations are about the origin of the cloud (the sensor for a raw scan).
//! Points are stored as f32 ([`PointCloud`]); the rotation runs in f64.

use autoshovel_point_cloud::{Point, PointCloud};
use nalgebra::{Matrix3, Vector3};

/// The matrix T of [RS eq. 11]: `level_from_sensor` for roll α and pitch β (rad).
#[rustfmt::skip]
pub fn level_from_sensor(roll_rad: f64, pitch_rad: f64) -> Matrix3<f64> {
    // [RS eq. 11]: T(α, β) as printed.
    let (sa, ca) = roll_rad.sin_cos();
    let (sb, cb) = pitch_rad.sin_cos();
    Matrix3::new(
        cb,       0.0, -sb,
        sa * sb,  ca,  sa * cb,
        ca * sb, -sa,  ca * cb,
    )
}

/// The inverse of T, `Tᵀ`: `sensor_from_level` for roll α and pitch β (rad).
pub fn sensor_from_level(roll_rad: f64, pitch_rad: f64) -> Matrix3<f64> {
    level_from_sensor(roll_rad, pitch_rad).transpose()
}

/// Eq. 12: the levelled cloud `p = T · p_s` for a sensor with roll α and
/// pitch β (rad) (see the module docs for which way they turn).
pub fn level(cloud: &[Point], roll_rad: f64, pitch_rad: f64) -> PointCloud {
    // [RS eq. 12]: p = T · p_s.
    rotate(cloud, &level_from_sensor(roll_rad, pitch_rad))
}

/// The inverse of [`level`], `p_s = Tᵀ · p`: what a sensor with roll α and
/// pitch β (rad) sees of a level scene. `tilt(level(c, α, β), α, β) == c` up
/// to rounding, and so is `level(tilt(c, α, β), α, β)`.
pub fn tilt(cloud: &[Point], roll_rad: f64, pitch_rad: f64) -> PointCloud {
    rotate(cloud, &sensor_from_level(roll_rad, pitch_rad))
}

/// Roll α and pitch β (rad) that make a plane with this normal (in sensor
/// coordinates) horizontal under [`level`]: `T(α, β) · n̂ = e_z`.
///
/// The normal need not be unit length; it is flipped to point up (`n_z > 0`)
/// first. Returns `None` for a zero or non-finite normal.
pub fn angles_from_normal(normal: [f64; 3]) -> Option<(f64, f64)> {
    let n = Vector3::from(normal);
    let len = n.norm();
    if !(len.is_finite() && len > 0.0) {
        return None;
    }
    let mut n = n / len;
    if n.z < 0.0 {
        n = -n;
    }
    let roll = (-n.y).clamp(-1.0, 1.0).asin();
    let pitch = n.x.atan2(n.z);
    Some((roll, pitch))
}

/// Apply a rotation to every point (f64 arithmetic, f32 storage).
pub(crate) fn rotate(cloud: &[Point], r: &Matrix3<f64>) -> PointCloud {
    use rayon::prelude::*;
    let points = cloud.par_iter().map(|p| rotate_point(r, p)).collect();
    PointCloud::new(points)
}

/// One point of [`rotate`]: `r · p` in f64, stored as f32.
#[inline]
pub(crate) fn rotate_point(r: &Matrix3<f64>, p: &[f32; 3]) -> [f32; 3] {
    let v = r * Vector3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
    [v.x as f32, v.y as f32, v.z as f32]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Rotation3;
    use proptest::prelude::*;

    #[test]
    fn t_is_eq_11_as_printed() {
        let (a, b) = (0.3_f64, -0.7_f64);
        let t = level_from_sensor(a, b);
        let printed = [
            [b.cos(), 0.0, -b.sin()],
            [a.sin() * b.sin(), a.cos(), a.sin() * b.cos()],
            [a.cos() * b.sin(), -a.sin(), a.cos() * b.cos()],
        ];
        for (i, row) in printed.iter().enumerate() {
            for (j, v) in row.iter().enumerate() {
                assert_relative_eq!(t[(i, j)], *v, epsilon = 1e-15);
            }
        }
    }

    #[test]
    fn t_is_rx_minus_alpha_times_ry_minus_beta() {
        let (a, b) = (0.21_f64, 0.13_f64);
        let rx = Rotation3::from_axis_angle(&Vector3::x_axis(), -a);
        let ry = Rotation3::from_axis_angle(&Vector3::y_axis(), -b);
        let composed = (rx * ry).into_inner();
        assert_relative_eq!(level_from_sensor(a, b), composed, epsilon = 1e-15);
    }

    #[test]
    fn positive_pitch_is_nose_up_positive_roll_is_left_side_down() {
        let t = level_from_sensor(0.0, 0.1);
        // The sensor's x axis in the level frame: first column of T.
        assert!(t[(2, 0)] > 0.0, "nose up");
        assert_relative_eq!(t[(2, 0)], 0.1_f64.sin(), epsilon = 1e-15);
        let t = level_from_sensor(0.1, 0.0);
        // The sensor's y axis in the level frame: second column of T.
        assert!(t[(2, 1)] < 0.0, "left side down");
        assert_relative_eq!(t[(2, 1)], -(0.1_f64.sin()), epsilon = 1e-15);
    }

    #[test]
    fn floor_normal_round_trip() {
        let (a, b) = (3.0_f64.to_radians(), (-2.0_f64).to_radians());
        let n = sensor_from_level(a, b) * Vector3::z();
        // The floor normal in sensor coordinates is T's last row.
        let t = level_from_sensor(a, b);
        for k in 0..3 {
            assert_relative_eq!(n[k], t[(2, k)], epsilon = 1e-15);
        }
        let (ra, rb) = angles_from_normal([n.x, n.y, n.z]).unwrap();
        assert_relative_eq!(ra, a, epsilon = 1e-14);
        assert_relative_eq!(rb, b, epsilon = 1e-14);
        // Downward normals and non-unit lengths give the same angles.
        let (ra, rb) = angles_from_normal([-2.0 * n.x, -2.0 * n.y, -2.0 * n.z]).unwrap();
        assert_relative_eq!(ra, a, epsilon = 1e-14);
        assert_relative_eq!(rb, b, epsilon = 1e-14);
        assert!(angles_from_normal([0.0, 0.0, 0.0]).is_none());
        assert!(angles_from_normal([f64::NAN, 0.0, 1.0]).is_none());
    }

    #[test]
    fn level_undoes_tilt_on_a_cloud() {
        let cloud = PointCloud::new(vec![[1.0, 2.0, 3.0], [-4.5, 0.25, -7.0], [0.0, 0.0, 0.0]]);
        let back = level(&tilt(&cloud, 0.05, -0.03), 0.05, -0.03);
        for (p, q) in cloud.points.iter().zip(&back.points) {
            for k in 0..3 {
                assert_relative_eq!(p[k], q[k], epsilon = 1e-5);
            }
        }
    }

    proptest! {
        #[test]
        fn t_is_a_rotation(a in -1.5f64..1.5, b in -1.5f64..1.5) {
            let t = level_from_sensor(a, b);
            let i = t.transpose() * t;
            prop_assert!((i - Matrix3::identity()).norm() < 1e-13);
            prop_assert!((t.determinant() - 1.0).abs() < 1e-13);
        }

        #[test]
        fn tilt_then_level_is_identity(
            a in -0.5f64..0.5, b in -0.5f64..0.5,
            x in -50.0f64..50.0, y in -50.0f64..50.0, z in -50.0f64..50.0,
        ) {
            let p = Vector3::new(x, y, z);
            let q = level_from_sensor(a, b) * (sensor_from_level(a, b) * p);
            prop_assert!((q - p).norm() < 1e-12 * (1.0 + p.norm()));
            let q = sensor_from_level(a, b) * (level_from_sensor(a, b) * p);
            prop_assert!((q - p).norm() < 1e-12 * (1.0 + p.norm()));
        }

        #[test]
        fn angles_from_normal_inverts_the_floor_normal(a in -1.2f64..1.2, b in -1.2f64..1.2) {
            let n = sensor_from_level(a, b) * Vector3::z();
            let (ra, rb) = angles_from_normal([n.x, n.y, n.z]).unwrap();
            prop_assert!((ra - a).abs() < 1e-12 && (rb - b).abs() < 1e-12);
            let up = level_from_sensor(ra, rb) * n;
            prop_assert!((up - Vector3::z()).norm() < 1e-12);
        }
    }
}
