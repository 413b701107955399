//! Angle helpers (SPEC §1: angles are compared wrapped to (−π, π]).

use std::f64::consts::PI;

/// Wraps an angle (rad) to (−π, π].
pub fn wrap_angle(a_rad: f64) -> f64 {
    let mut a = a_rad % (2.0 * PI);
    if a <= -PI {
        a += 2.0 * PI;
    } else if a > PI {
        a -= 2.0 * PI;
    }
    a
}

/// Signed smallest difference `a − b` (rad), wrapped to (−π, π].
pub fn angle_diff(a_rad: f64, b_rad: f64) -> f64 {
    wrap_angle(a_rad - b_rad)
}

/// Degrees → radians.
pub fn rad(deg: f64) -> f64 {
    deg.to_radians()
}

/// Radians → degrees.
pub fn deg(rad: f64) -> f64 {
    rad.to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn wraps_to_half_open_interval() {
        assert_relative_eq!(wrap_angle(PI), PI);
        assert_relative_eq!(wrap_angle(-PI), PI);
        assert_relative_eq!(wrap_angle(3.0 * PI), PI, epsilon = 1e-12);
        assert_relative_eq!(
            angle_diff(rad(179.0), rad(-179.0)),
            rad(-2.0),
            epsilon = 1e-12
        );
    }

    proptest! {
        #[test]
        fn wrapped_angle_is_equivalent_and_in_range(a in -1e3f64..1e3) {
            let w = wrap_angle(a);
            prop_assert!(w > -PI - 1e-12 && w <= PI + 1e-12);
            // Same direction on the unit circle.
            prop_assert!((w.cos() - a.cos()).abs() < 1e-9 && (w.sin() - a.sin()).abs() < 1e-9);
        }
    }
}
