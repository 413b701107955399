//! Polyline measures: length, cumulative arc length, discrete curvature and the
//! nearest point of a segment.

use crate::Vec2;

/// Total length of a polyline (m).
pub fn polyline_length(points: &[Vec2]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// Cumulative arc length at each vertex, starting at 0 (m).
pub fn arc_lengths(points: &[Vec2]) -> Vec<f64> {
    let mut s = Vec::with_capacity(points.len());
    let mut acc = 0.0;
    for (i, p) in points.iter().enumerate() {
        if i > 0 {
            acc += (p - points[i - 1]).norm();
        }
        s.push(acc);
    }
    s
}

/// Signed curvature (1/m) of the circle through three points (Menger
/// curvature, positive when turning left); 0 for collinear or repeated points.
pub fn menger_curvature(a: Vec2, b: Vec2, c: Vec2) -> f64 {
    let ab = b - a;
    let bc = c - b;
    let ca = a - c;
    let denom = ab.norm() * bc.norm() * ca.norm();
    if denom <= 1e-15 {
        return 0.0;
    }
    2.0 * (ab.x * bc.y - ab.y * bc.x) / denom
}

/// Nearest point to `p` on the segment `a`–`b`, with its parameter t ∈ [0, 1].
/// (Inlined across crates: it sits in every distance query's inner loop.)
#[inline]
pub fn segment_nearest(p: Vec2, a: Vec2, b: Vec2) -> (Vec2, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    if len2 <= 0.0 {
        return (a, 0.0);
    }
    let t = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
    (a + ab * t, t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn curvature_of_points_on_a_circle_is_one_over_radius() {
        let r = 7.5;
        let p = |a: f64| Vec2::new(r * a.cos(), r * a.sin());
        assert_relative_eq!(
            menger_curvature(p(0.1), p(0.4), p(0.9)),
            1.0 / r,
            epsilon = 1e-12
        );
        // Clockwise → negative.
        assert_relative_eq!(
            menger_curvature(p(0.9), p(0.4), p(0.1)),
            -1.0 / r,
            epsilon = 1e-12
        );
    }

    #[test]
    fn lengths_add_up() {
        let pts = [
            Vec2::new(0.0, 0.0),
            Vec2::new(3.0, 4.0),
            Vec2::new(3.0, 10.0),
        ];
        assert_relative_eq!(polyline_length(&pts), 11.0);
        assert_eq!(arc_lengths(&pts).len(), 3);
        assert_relative_eq!(arc_lengths(&pts)[1], 5.0);
    }

    #[test]
    fn nearest_point_is_clamped_to_the_segment() {
        let (q, t) = segment_nearest(Vec2::new(-1.0, 1.0), Vec2::zeros(), Vec2::new(2.0, 0.0));
        assert_relative_eq!(q, Vec2::zeros());
        assert_relative_eq!(t, 0.0);
        let (q, _) = segment_nearest(Vec2::new(1.0, 1.0), Vec2::zeros(), Vec2::new(2.0, 0.0));
        assert_relative_eq!(q, Vec2::new(1.0, 0.0));
    }
}
