//! Small helpers every filter shares: errors, finite points, the f32
//! radius that matches PCL's f64 comparison.

use crate::{CloudError, Point, PointCloud, Result};

/// The error of a filter given an empty cloud.
pub(crate) fn empty_input(filter: &'static str) -> CloudError {
    CloudError::Emptied {
        filter,
        input: 0,
        hint: "the input cloud is empty: check the previous stage".into(),
    }
}

/// The error of a filter that removed every point.
pub(crate) fn emptied(filter: &'static str, input: usize, hint: &str) -> CloudError {
    CloudError::Emptied {
        filter,
        input,
        hint: hint.into(),
    }
}

/// A bad parameter of `filter`.
pub(crate) fn bad(filter: &'static str, what: String) -> CloudError {
    CloudError::BadParameter { filter, what }
}

/// Whether a point has three finite coordinates.
pub(crate) fn is_finite(p: &Point) -> bool {
    p.iter().all(|v| v.is_finite())
}

/// The largest f32 `t` with `t as f64 <= x`: comparing an f32 squared
/// distance `d <= t` is then the same as PCL's `(double) d <= x`.
pub(crate) fn f32_at_most(x: f64) -> f32 {
    let t = x as f32;
    if f64::from(t) > x {
        next_down(t)
    } else {
        t
    }
}

/// The next f32 towards −∞ (`f32::next_down`, stable only since Rust 1.86).
fn next_down(t: f32) -> f32 {
    if t.is_nan() || t == f32::NEG_INFINITY {
        t
    } else if t == 0.0 {
        -f32::from_bits(1)
    } else if t > 0.0 {
        f32::from_bits(t.to_bits() - 1)
    } else {
        f32::from_bits(t.to_bits() + 1)
    }
}

/// Runs `kept` (which returns kept indices into the slice it is given) on
/// the finite points of `cloud` only and maps the indices back: PCL's tools
/// drop non-finite points before these filters, and so do we. Clouds built
/// by this crate's readers are finite already, which costs one scan.
pub(crate) fn on_finite_points<F>(cloud: &[Point], kept: F) -> Result<Vec<usize>>
where
    F: FnOnce(&[Point]) -> Result<Vec<usize>>,
{
    if cloud.iter().all(is_finite) {
        return kept(cloud);
    }
    let index: Vec<usize> = (0..cloud.len()).filter(|&i| is_finite(&cloud[i])).collect();
    let finite: Vec<Point> = index.iter().map(|&i| cloud[i]).collect();
    Ok(kept(&finite)?.into_iter().map(|i| index[i]).collect())
}

/// The points of `cloud` at `indices`, in that order.
pub(crate) fn gather(cloud: &[Point], indices: &[usize]) -> PointCloud {
    PointCloud::new(indices.iter().map(|&i| cloud[i]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f32_at_most_rounds_down() {
        // 0.1 * 0.1 in f64 lies between two f32 values; the lower one is taken.
        let x = 0.1_f64 * 0.1;
        let t = f32_at_most(x);
        assert!(f64::from(t) <= x);
        assert!(f64::from(f32::from_bits(t.to_bits() + 1)) > x);
        // Exactly representable values are kept.
        assert_eq!(f32_at_most(0.0625), 0.0625_f32);
        assert_eq!(f32_at_most(f64::INFINITY), f32::INFINITY);
    }
}
