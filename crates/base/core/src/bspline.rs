//! Clamped uniform B-splines, used to smooth planned paths (electric-shovel
//! paper §3.3, "cubic B-spline curve").
//!
//! The clamped knot vector makes the curve start at the first control point
//! and end at the last, with end tangents along the first and last legs of the
//! control polygon. Evaluation is de Boor's algorithm; derivatives are the
//! derivative splines (Piegl & Tiller, *The NURBS Book*, eq. 3.8).

use crate::Vec2;

/// A clamped B-spline curve in the plane, of degree ≤ 3.
#[derive(Debug, Clone)]
pub struct CubicBSpline {
    degree: usize,
    knots: Vec<f64>,
    ctrl: Vec<Vec2>,
}

impl CubicBSpline {
    /// The clamped uniform cubic B-spline of the given control points, with
    /// parameter u ∈ [0, 1]. With fewer than four control points the degree
    /// drops to `len − 1` (a line for two points). Returns `None` for fewer
    /// than two points.
    pub fn clamped(ctrl: Vec<Vec2>) -> Option<Self> {
        if ctrl.len() < 2 {
            return None;
        }
        let degree = 3.min(ctrl.len() - 1);
        let n = ctrl.len();
        let interior = n - degree - 1;
        let mut knots = Vec::with_capacity(n + degree + 1);
        knots.extend(std::iter::repeat_n(0.0, degree + 1));
        for i in 1..=interior {
            knots.push(i as f64 / (interior + 1) as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        Some(Self {
            degree,
            knots,
            ctrl,
        })
    }

    /// Degree of the curve.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The control points.
    pub fn control_points(&self) -> &[Vec2] {
        &self.ctrl
    }

    /// Point at parameter u ∈ [0, 1] (clamped outside).
    pub fn point(&self, u: f64) -> Vec2 {
        let u = u.clamp(0.0, 1.0);
        let p = self.degree;
        let k = self.span(u);
        // de Boor
        let mut d: Vec<Vec2> = (0..=p).map(|j| self.ctrl[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let denom = self.knots[i + p + 1 - r] - self.knots[i];
                let alpha = if denom > 0.0 {
                    (u - self.knots[i]) / denom
                } else {
                    0.0
                };
                d[j] = d[j - 1] * (1.0 - alpha) + d[j] * alpha;
            }
        }
        d[p]
    }

    /// The derivative curve d/du (degree one lower), or `None` for a degree-0 curve.
    pub fn derivative(&self) -> Option<Self> {
        if self.degree == 0 {
            return None;
        }
        let p = self.degree;
        let ctrl = (0..self.ctrl.len() - 1)
            .map(|i| {
                let denom = self.knots[i + p + 1] - self.knots[i + 1];
                if denom > 0.0 {
                    (self.ctrl[i + 1] - self.ctrl[i]) * (p as f64 / denom)
                } else {
                    Vec2::zeros()
                }
            })
            .collect();
        let knots = self.knots[1..self.knots.len() - 1].to_vec();
        Some(Self {
            degree: p - 1,
            knots,
            ctrl,
        })
    }

    /// Knot span index k with knots[k] ≤ u < knots[k+1] (last span at u = 1).
    fn span(&self, u: f64) -> usize {
        let n = self.ctrl.len() - 1;
        if u >= self.knots[n + 1] {
            return n;
        }
        // Knots are few (tens): a linear scan is faster than bisection here.
        let mut k = self.degree;
        while k < n && u >= self.knots[k + 1] {
            k += 1;
        }
        k
    }

    /// Samples the curve at (about) every `ds_m` metres of arc length.
    /// Each sample is (point, unit tangent, signed curvature (1/m)). The last
    /// sample is the curve's end point.
    pub fn sample_by_arc_length(&self, ds_m: f64) -> Vec<CurveSample> {
        let d1 = self.derivative();
        let d2 = d1.as_ref().and_then(|d| d.derivative());
        // Dense parameter table for the arc length.
        let dense = (self.ctrl.len() * 40).max(200);
        let mut us = Vec::with_capacity(dense + 1);
        let mut ss = Vec::with_capacity(dense + 1);
        let mut prev = self.point(0.0);
        let mut s = 0.0;
        for i in 0..=dense {
            let u = i as f64 / dense as f64;
            let q = self.point(u);
            s += (q - prev).norm();
            prev = q;
            us.push(u);
            ss.push(s);
        }
        let total = s;
        let count = if ds_m > 0.0 && total > 0.0 {
            (total / ds_m).ceil().max(1.0) as usize
        } else {
            1
        };
        let mut out = Vec::with_capacity(count + 1);
        let mut j = 0;
        for i in 0..=count {
            let target = total * i as f64 / count as f64;
            while j + 1 < ss.len() && ss[j + 1] < target {
                j += 1;
            }
            let u = if j + 1 < ss.len() && ss[j + 1] > ss[j] {
                let t = ((target - ss[j]) / (ss[j + 1] - ss[j])).clamp(0.0, 1.0);
                us[j] + t * (us[j + 1] - us[j])
            } else {
                us[j]
            };
            let point = self.point(u);
            let (tangent, curvature) = match (&d1, &d2) {
                (Some(d1), d2) => {
                    let v = d1.point(u);
                    let a = d2.as_ref().map(|d| d.point(u)).unwrap_or_else(Vec2::zeros);
                    let speed = v.norm();
                    if speed > 1e-12 {
                        (v / speed, (v.x * a.y - v.y * a.x) / speed.powi(3))
                    } else {
                        (Vec2::zeros(), 0.0)
                    }
                }
                _ => (Vec2::zeros(), 0.0),
            };
            out.push(CurveSample {
                point,
                tangent,
                curvature,
                s: target,
            });
        }
        out
    }
}

/// One sample of a curve.
#[derive(Debug, Clone, Copy)]
pub struct CurveSample {
    /// Position (m).
    pub point: Vec2,
    /// Unit tangent (zero where the curve stalls).
    pub tangent: Vec2,
    /// Signed curvature, positive turning left (1/m).
    pub curvature: f64,
    /// Arc length from the curve's start (m).
    pub s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn square_ctrl() -> Vec<Vec2> {
        vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 2.0),
            Vec2::new(3.0, 3.0),
            Vec2::new(4.0, 1.0),
            Vec2::new(6.0, 0.0),
            Vec2::new(7.0, 2.0),
        ]
    }

    #[test]
    fn clamped_curve_interpolates_its_ends_with_tangents_along_the_end_legs() {
        let c = CubicBSpline::clamped(square_ctrl()).unwrap();
        assert_relative_eq!(c.point(0.0), Vec2::new(0.0, 0.0), epsilon = 1e-12);
        assert_relative_eq!(c.point(1.0), Vec2::new(7.0, 2.0), epsilon = 1e-12);
        let d = c.derivative().unwrap();
        let t0 = d.point(0.0).normalize();
        let t1 = d.point(1.0).normalize();
        assert_relative_eq!(t0, Vec2::new(1.0, 2.0).normalize(), epsilon = 1e-12);
        assert_relative_eq!(t1, Vec2::new(1.0, 2.0).normalize(), epsilon = 1e-12);
    }

    #[test]
    fn collinear_control_points_give_a_straight_line_of_zero_curvature() {
        let ctrl: Vec<Vec2> = (0..7)
            .map(|i| Vec2::new(i as f64, 0.5 * i as f64))
            .collect();
        let c = CubicBSpline::clamped(ctrl).unwrap();
        let samples = c.sample_by_arc_length(0.1);
        let len = (36.0f64 + 9.0).sqrt();
        assert_relative_eq!(samples.last().unwrap().s, len, epsilon = 1e-6);
        for s in samples {
            assert_relative_eq!(s.curvature, 0.0, epsilon = 1e-9);
            assert_relative_eq!(s.point.y, 0.5 * s.point.x, epsilon = 1e-9);
        }
    }

    #[test]
    fn derivative_matches_finite_differences() {
        let c = CubicBSpline::clamped(square_ctrl()).unwrap();
        let d = c.derivative().unwrap();
        for i in 1..20 {
            let u = i as f64 / 20.0;
            let h = 1e-6;
            let fd = (c.point(u + h) - c.point(u - h)) / (2.0 * h);
            assert_relative_eq!(d.point(u), fd, epsilon = 1e-5, max_relative = 1e-6);
        }
    }

    #[test]
    fn curve_stays_in_the_convex_hull_of_its_control_points() {
        // Here: the bounding box, a weaker but exact consequence.
        let c = CubicBSpline::clamped(square_ctrl()).unwrap();
        for s in c.sample_by_arc_length(0.05) {
            assert!(s.point.x >= -1e-12 && s.point.x <= 7.0 + 1e-12);
            assert!(s.point.y >= -1e-12 && s.point.y <= 3.0 + 1e-12);
        }
    }

    proptest! {
        #[test]
        fn arc_length_samples_are_evenly_spaced(ys in proptest::collection::vec(-3.0f64..3.0, 4..12)) {
            let ctrl: Vec<Vec2> = ys.iter().enumerate().map(|(i, y)| Vec2::new(2.0 * i as f64, *y)).collect();
            let c = CubicBSpline::clamped(ctrl).unwrap();
            let s = c.sample_by_arc_length(0.2);
            let gaps: Vec<f64> = s.windows(2).map(|w| (w[1].point - w[0].point).norm()).collect();
            let max = gaps.iter().cloned().fold(0.0, f64::max);
            let min = gaps.iter().cloned().fold(f64::INFINITY, f64::min);
            // Chords of a dense table: within 1 % of the requested spacing.
            prop_assert!(max <= 0.2 * 1.01, "max gap {max}");
            prop_assert!(min >= 0.9 * max, "min gap {min}, max gap {max}");
        }
    }
}
