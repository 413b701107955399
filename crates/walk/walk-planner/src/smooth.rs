//! Cubic B-spline smoothing of a raw potential-field polyline
//! (electric-shovel paper §3.3), then resampling by arc length.
//!
//! The paper does not say how the control points are chosen. We decimate the
//! raw polyline to about one control point per `control_spacing_m` (keeping
//! the start, the end of the lead-in and the goal), so the spline cuts the
//! descent's zig-zags while its clamped ends keep the start point and the
//! arrival direction. The caller checks clearance and halves the spacing when
//! the smoothed curve cuts a corner too close.

use autoshovel_core::{CubicBSpline, CurveSample, Vec2};
use serde::{Deserialize, Serialize};

/// Smoothing parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SmoothParams {
    /// Target distance between B-spline control points (m).
    pub control_spacing_m: f64,
    /// Spacing of the output samples (m).
    pub sample_spacing_m: f64,
    /// Smallest control spacing tried when the smoothed path collides (m).
    pub min_control_spacing_m: f64,
}

impl Default for SmoothParams {
    fn default() -> Self {
        Self {
            control_spacing_m: 1.0,
            sample_spacing_m: 0.1,
            min_control_spacing_m: 0.1,
        }
    }
}

/// Picks control points from `raw`: the next raw point at least `spacing_m`
/// (straight-line) from the last control point, always keeping the first
/// point, the point at index `keep` (end of the lead-in) and the last point.
/// Measuring from the last kept point, not along the polyline, drops the
/// back-and-forth of a descent that hesitated.
pub fn decimate(raw: &[Vec2], spacing_m: f64, keep: usize) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::new();
    let Some(&first) = raw.first() else {
        return out;
    };
    out.push(first);
    for i in 1..raw.len() {
        let last = i + 1 == raw.len();
        let from_kept = (raw[i] - out[out.len() - 1]).norm();
        if last || i == keep || from_kept >= spacing_m {
            // Avoid a near-duplicate final control point (it would bend the end tangent).
            if last
                && from_kept < 0.5 * spacing_m
                && out.len() > 1
                && i != keep
                && out.len() - 1 != keep_index(&out, raw, keep)
            {
                out.pop();
            }
            out.push(raw[i]);
        }
    }
    // The clamped spline leaves along its last control leg: make that leg the
    // descent's own final approach (the raw point about a fifth of the
    // spacing before the goal), not a chord of the last metre's curve.
    let n = out.len();
    if n >= 3 && raw.len() >= 3 {
        let goal = raw[raw.len() - 1];
        let near = 0.2 * spacing_m;
        if (out[n - 1] - out[n - 2]).norm() > 1.5 * near {
            if let Some(q) = raw
                .iter()
                .rev()
                .skip(1)
                .find(|q| (**q - goal).norm() >= near)
            {
                if (q - out[n - 2]).norm() > 1e-9 {
                    out.insert(n - 1, *q);
                }
            }
        }
    }
    out
}

/// Index in `out` of the lead-in control point (raw[keep]), or usize::MAX.
fn keep_index(out: &[Vec2], raw: &[Vec2], keep: usize) -> usize {
    raw.get(keep)
        .and_then(|k| out.iter().position(|p| p == k))
        .unwrap_or(usize::MAX)
}

/// Smooths `raw` into samples spaced `sample_spacing_m` apart.
pub fn smooth(
    raw: &[Vec2],
    control_spacing_m: f64,
    sample_spacing_m: f64,
    keep: usize,
) -> Vec<CurveSample> {
    let ctrl = decimate(raw, control_spacing_m, keep);
    match CubicBSpline::clamped(ctrl) {
        Some(spline) => spline.sample_by_arc_length(sample_spacing_m),
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn decimation_keeps_ends_and_spacing() {
        let raw: Vec<Vec2> = (0..=100).map(|i| Vec2::new(0.1 * i as f64, 0.0)).collect();
        let c = decimate(&raw, 1.0, 10);
        assert_relative_eq!(c[0], raw[0]);
        assert_relative_eq!(*c.last().unwrap(), raw[100]);
        assert!(c.contains(&raw[10]));
        assert!(c.len() >= 10 && c.len() <= 12, "{}", c.len());
    }

    #[test]
    fn the_end_tangent_is_the_descents_final_approach() {
        // A quarter circle of radius 5 from (0, 0) heading +x to (5, 5) heading +y: the chord of
        // its last metre is ~6° off, the final approach is not.
        let raw: Vec<Vec2> = (0..=80)
            .map(|i| {
                let a = std::f64::consts::FRAC_PI_2 * i as f64 / 80.0;
                Vec2::new(5.0 * a.sin(), 5.0 - 5.0 * a.cos())
            })
            .collect();
        let s = smooth(&raw, 1.0, 0.1, 0);
        let t = s.last().unwrap().tangent;
        let err = t.y.atan2(t.x).to_degrees() - 90.0;
        assert!(err.abs() < 2.5, "end tangent {err} deg off");
    }

    #[test]
    fn zigzag_is_smoothed_towards_its_mean_line() {
        // A descent oscillating ±5 cm about y = 0 (settling onto it for the
        // last half metre, as a descent does at its goal) becomes (nearly) straight.
        let raw: Vec<Vec2> = (0..=200)
            .map(|i| {
                let y = if i > 195 {
                    0.0
                } else if i % 2 == 0 {
                    0.05
                } else {
                    -0.05
                };
                Vec2::new(0.1 * i as f64, y)
            })
            .collect();
        let s = smooth(&raw, 1.0, 0.1, 0);
        let max_dev = s.iter().map(|c| c.point.y.abs()).fold(0.0, f64::max);
        assert!(max_dev <= 0.05 + 1e-12);
        let max_kappa = s
            .iter()
            .skip(2)
            .map(|c| c.curvature.abs())
            .fold(0.0, f64::max);
        assert!(max_kappa < 0.5, "curvature {max_kappa}");
    }
}
