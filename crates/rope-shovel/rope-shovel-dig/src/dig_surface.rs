//! The pile as the dig planner sees it: the surface z = f(x, y) of [RS eq. 21],
//! averaged across the dipper width and tabulated along the dig plane, in the
//! dig frame {Oo} (origin at the toe, x into the pile, y up).
//!
//! [RS eq. 28] integrates f(x, y) − g(x, y) over the strip the dipper sweeps. The
//! tooth path does not vary across the dipper, so the double integral is
//! exactly b·∫(f̄(x) − g(x)) dx with f̄ the mean of f across the width b:
//! [`DigSurface`] stores f̄ on a 1 mm grid (5-point Gauss–Legendre across the
//! width). The planner then integrates in path coordinates: the cut
//! thickness c normal to the path (which also gives the resistance
//! F_τ = k_F·b·c at each instant) and the area element (1 − κλ) dλ ds, so
//! V = b∫(c − κc²/2) ds ([`swept_width`]) — exact while the path's radius of
//! curvature exceeds the cut thickness (see
//! `tests::path_integral_matches_the_area_between_path_and_surface`).

use autoshovel_terrain::{PileParams, PileShape, SurfaceFit};

use crate::error::{DigError, Result};

/// Gauss–Legendre nodes and weights on [−1, 1], 5 points.
const GL5: [(f64, f64); 5] = [
    (0.0, 0.568_888_888_888_888_9),
    (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// Grid step of the tabulated profile (m).
const DX: f64 = 0.001;

/// A pile profile in the dig frame, width-averaged (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct DigSurface {
    /// x of the first sample (m).
    x0: f64,
    /// Heights f̄ at x0 + i·DX (m).
    heights: Vec<f64>,
    /// Where it came from, for reports.
    pub source: String,
    /// A cut thicker than this is taken as "everything" (the normal never
    /// leaves the material) (m): 4 m, a hundred times the scale model's
    /// deepest cut; [`DigSurface::with_deepest_cut`] sets it for a larger
    /// machine.
    deepest_cut_m: f64,
}

/// The default of [`DigSurface::with_deepest_cut`] (m).
pub const DEEPEST_CUT_M: f64 = 4.0;

impl DigSurface {
    /// Tabulate `f(x, y_across)` (dig-frame height) averaged over |y| ≤ b/2,
    /// for x in `[x0, x1]`.
    pub fn from_fn(
        f: impl Fn(f64, f64) -> f64,
        width_m: f64,
        x0: f64,
        x1: f64,
        source: &str,
    ) -> Self {
        let n = ((x1 - x0) / DX).ceil().max(1.0) as usize + 1;
        let heights = (0..n)
            .map(|i| {
                let x = x0 + i as f64 * DX;
                GL5.iter()
                    .map(|&(node, w)| 0.5 * w * f(x, 0.5 * width_m * node))
                    .sum::<f64>()
            })
            .collect();
        Self {
            x0,
            heights,
            source: source.to_string(),
            deepest_cut_m: DEEPEST_CUT_M,
        }
    }

    /// The same profile with cuts thicker than `m` taken as "everything"
    /// (by default [`DEEPEST_CUT_M`], for the scale model; λ times that for
    /// a machine λ times as large).
    pub fn with_deepest_cut(mut self, m: f64) -> Self {
        self.deepest_cut_m = m;
        self
    }

    /// The noiseless synthetic pile of [`autoshovel_terrain::generate_pile`]
    /// at the paper's 1:30 scale, cut along its centre line (y = 0).
    pub fn from_shape(shape: PileShape, width_m: f64) -> Self {
        let p = PileParams {
            shape,
            ..PileParams::paper_model()
        };
        Self::from_pile(&p, 0.0, width_m)
    }

    /// The noiseless pile `p` of [`autoshovel_terrain::generate_pile`] with
    /// its toe (on the centre line) at `toe_x_m` in the dig frame: a positive
    /// value puts the toe that far beyond where the dig starts.
    pub fn from_pile(p: &PileParams, toe_x_m: f64, width_m: f64) -> Self {
        let toe = p.toe_x_m(0.0);
        let floor = -p.scale * p.sensor_height_m;
        let (xs, _) = p.window_m();
        Self::from_fn(
            |x, y| p.height_at(x - toe_x_m + toe, y) - floor,
            width_m,
            -0.1,
            xs[1] - toe + toe_x_m.max(0.0),
            &format!(
                "{} pile (1:30 model, face {:.3} m, toe at {:+.3} m)",
                p.shape.name(),
                p.scale * p.face_height_m,
                toe_x_m
            ),
        )
    }

    /// A fitted surface ([RS eq. 21]) in the levelled sensor frame, with the floor
    /// at height `floor_z`: the dig plane is y = `y_line`. The toe is where
    /// the width-averaged profile climbs out of the floor: the last sample at
    /// most `toe_rise_m` above it before the climb to the top, moved back
    /// down the face along its slope to the floor. When the fitted extent
    /// starts on the face already, the face is continued down to the floor.
    pub fn from_fit(
        fit: &SurfaceFit,
        floor_z: f64,
        y_line: f64,
        width_m: f64,
        toe_rise_m: f64,
    ) -> Result<Self> {
        let (x_lo, x_hi) = (fit.extent.x_min_m, fit.extent.x_max_m);
        let raw = Self::from_fn(
            |x, y| fit.height(x, y_line + y) - floor_z, // [RS eq. 21]
            width_m,
            x_lo,
            x_hi,
            "fitted surface",
        );
        raw.from_toe(toe_rise_m).map(|(surface, _)| surface)
    }

    /// This profile (heights above the floor along a line, from `x0`) in
    /// the dig frame: x measured from the toe, where the profile climbs out
    /// of the floor — the last sample at most `toe_rise_m` above it before
    /// the climb to the top, moved back down the face along its slope to
    /// the floor. When the profile starts on the face already, the face is
    /// continued down to the floor. Returns the profile and the toe's
    /// position on the original line.
    pub fn from_toe(self, toe_rise_m: f64) -> Result<(Self, f64)> {
        let raw = self;
        let (x_lo, x_hi) = raw.x_range();
        let top = raw
            .heights
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max);
        if top.is_nan() || top <= 2.0 * toe_rise_m {
            return Err(DigError::Surface(format!(
                "the fitted surface rises only {top:.3} m above the floor; no pile to dig"
            )));
        }
        // The toe: the last floor-level sample before the profile climbs to its top.
        let i_top = raw
            .heights
            .iter()
            .position(|&h| h >= 0.9 * top)
            .unwrap_or(0);
        let Some(i_toe) = raw.heights[..=i_top].iter().rposition(|&h| h <= toe_rise_m) else {
            return Self::extrapolate_toe(raw, x_lo, x_hi);
        };
        // Refine: back down the face from the first sample above the
        // threshold along the slope of the next 20 mm, so the toe is where
        // the face meets the floor, not where it is toe_rise_m above it.
        let i_up = (i_toe + 1).min(raw.heights.len() - 1);
        let k = (i_up + 20).min(raw.heights.len() - 1);
        let slope = if k > i_up {
            (raw.heights[k] - raw.heights[i_up]) / ((k - i_up) as f64 * DX)
        } else {
            0.0
        };
        let back = if slope > 0.0 {
            (raw.heights[i_up] / slope).clamp(0.0, 10.0 * toe_rise_m)
        } else {
            0.0
        };
        let x_toe = raw.x0 + i_up as f64 * DX - back;
        let source = format!("{} (toe at x = {x_toe:.3} m)", raw.source);
        Ok((
            Self {
                x0: raw.x0 - x_toe,
                source,
                ..raw
            },
            x_toe,
        ))
    }

    /// The fit starts on the face (perception removes the floor points, so a
    /// pile that rises steeply from its toe has no floor inside the fitted
    /// extent): continue the face down to the floor along its slope over the
    /// first 20 mm, and put the toe where it meets the floor.
    fn extrapolate_toe(raw: Self, x_lo: f64, x_hi: f64) -> Result<(Self, f64)> {
        let k = 20.min(raw.heights.len() - 1);
        let h0 = raw.heights[0];
        let slope = (raw.heights[k] - h0) / (k as f64 * DX);
        let run = if slope > 0.0 {
            h0 / slope
        } else {
            f64::INFINITY
        };
        if run.is_nan() || run > 0.25 * (x_hi - x_lo) {
            return Err(DigError::Surface(format!(
                "no toe: the fitted surface starts {h0:.3} m above the floor at x = {x_lo:.3} m \
                 and does not fall towards it (scan nearer the machine)"
            )));
        }
        let n = (run / DX).ceil() as usize;
        let x_toe = x_lo - n as f64 * DX;
        let mut heights: Vec<f64> = (0..n).map(|i| h0 * i as f64 / n as f64).collect();
        heights.extend_from_slice(&raw.heights);
        Ok((Self {
            x0: 0.0,
            heights,
            deepest_cut_m: raw.deepest_cut_m,
            source: format!(
                "fitted surface (toe extrapolated {:.3} m before the scan, at sensor x = {x_toe:.3} m)",
                n as f64 * DX
            ),
        }, x_toe))
    }

    /// The x range tabulated (m).
    pub fn x_range(&self) -> (f64, f64) {
        (self.x0, self.x0 + (self.heights.len() - 1) as f64 * DX)
    }

    /// Highest point of the profile (m).
    pub fn top(&self) -> f64 {
        self.heights
            .iter()
            .cloned()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// f̄(x), linear between samples, held at the ends (m).
    #[inline]
    pub fn height(&self, x: f64) -> f64 {
        let u = (x - self.x0) / DX;
        if u.is_nan() || u <= 0.0 {
            return self.heights[0];
        }
        // (u may be +∞: `as` saturates, and the comparison cannot overflow)
        let i = u as usize;
        if i >= self.heights.len() - 1 {
            return *self.heights.last().expect("non-empty");
        }
        let f = u - i as f64;
        self.heights[i] + f * (self.heights[i + 1] - self.heights[i])
    }

    /// Thickness of material above the point `p` measured along the unit
    /// normal `n` (0 when `p` is above the surface): the cut thickness c.
    #[inline]
    pub fn cut_thickness(&self, p: [f64; 2], n: [f64; 2]) -> f64 {
        let below = |l: f64| self.height(p[0] + l * n[0]) - (p[1] + l * n[1]);
        if below(0.0) <= 0.0 {
            return 0.0;
        }
        // Bracket with doubling steps from 5 mm, then regula falsi with the
        // Illinois modification to 1 µm (the profile is piecewise linear).
        let (mut lo, mut f_lo) = (0.0, below(0.0));
        let mut hi = 0.005;
        let mut f_hi = below(hi);
        while f_hi > 0.0 {
            (lo, f_lo) = (hi, f_hi);
            hi *= 2.0;
            if hi > self.deepest_cut_m {
                return hi;
            }
            f_hi = below(hi);
        }
        let mut side = 0i8;
        for _ in 0..40 {
            let mid = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
            if hi - lo < 1e-6 {
                break;
            }
            let f_mid = below(mid);
            if f_mid > 0.0 {
                (lo, f_lo) = (mid, f_mid);
                if side == 1 {
                    f_hi *= 0.5;
                }
                side = 1;
            } else {
                (hi, f_hi) = (mid, f_mid);
                if side == -1 {
                    f_lo *= 0.5;
                }
                side = -1;
            }
            if f_mid.abs() < 1e-9 {
                return mid;
            }
        }
        (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
    }

    /// The profile as (x, y) samples every `step` metres over `[x0, x1]`.
    pub fn polyline(&self, x0: f64, x1: f64, step: f64) -> Vec<[f64; 2]> {
        let n = ((x1 - x0) / step).ceil().max(1.0) as usize;
        (0..=n)
            .map(|i| {
                let x = x0 + (x1 - x0) * i as f64 / n as f64;
                [x, self.height(x)]
            })
            .collect()
    }
}

/// Area swept per unit path length (the integrand of [RS eq. 28]) by a
/// cut of normal thickness `c` on a
/// path of signed curvature `kappa` (positive when it bends towards the
/// material, i.e. to the left of travel): the strip between the path and the
/// surface in path coordinates has area element (1 − κλ) dλ ds, so
/// dA/ds = c − κc²/2. Exact for κc < 1.
#[inline]
pub fn swept_width(c: f64, kappa: f64) -> f64 {
    c - 0.5 * kappa * c * c // the integrand of [RS eq. 28] per unit width
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::PI;

    #[test]
    fn a_pile_moved_back_is_the_same_profile_shifted() {
        let p = PileParams {
            shape: PileShape::Convex,
            face_height_m: 8.0,
            ..PileParams::paper_model()
        };
        let at_start = DigSurface::from_pile(&p, 0.0, 0.12);
        let moved = DigSurface::from_pile(&p, 0.03, 0.12);
        for k in 0..60 {
            let x = 0.01 * k as f64;
            assert_relative_eq!(moved.height(x + 0.03), at_start.height(x), epsilon = 1e-9);
        }
        // Floor before the toe, the 8 m face (at 1:30) on top.
        assert_relative_eq!(moved.height(0.02), 0.0, epsilon = 1e-12);
        assert_relative_eq!(moved.top(), 8.0 / 30.0, epsilon = 1e-9);
        // The built-in pile is the Fig. 7 model with its toe at the start.
        let fig7 = PileParams {
            shape: PileShape::Convex,
            ..PileParams::paper_model()
        };
        assert_eq!(
            DigSurface::from_shape(PileShape::Convex, 0.12).height(0.2),
            DigSurface::from_pile(&fig7, 0.0, 0.12).height(0.2)
        );
    }

    #[test]
    fn heights_are_held_past_the_ends_even_at_infinity() {
        let s = DigSurface::from_fn(|x, _| x, 0.12, 0.0, 0.5, "ramp");
        assert_eq!(s.height(f64::INFINITY), s.height(0.5));
        assert_eq!(s.height(1e300), s.height(0.5));
        assert_eq!(s.height(f64::NEG_INFINITY), s.height(0.0));
        assert_eq!(s.height(f64::NAN), s.height(0.0));
    }

    #[test]
    fn width_average_of_a_plane_is_its_centre_line() {
        let s = DigSurface::from_fn(|x, y| 0.8 * x + 0.3 * y, 0.12, 0.0, 0.5, "plane");
        assert_relative_eq!(s.height(0.2), 0.16, epsilon = 1e-12);
        // A parabola across the width averages to its mean: y² → b²/12.
        let s = DigSurface::from_fn(|_, y| y * y, 0.12, 0.0, 0.1, "bowl");
        assert_relative_eq!(s.height(0.05), 0.12 * 0.12 / 12.0, epsilon = 1e-15);
    }

    #[test]
    fn cut_thickness_under_a_plane_face_is_the_distance_to_it() {
        // Face y = x tan 40°; a point 2 cm inside along the face normal.
        let a = 40f64.to_radians();
        let s = DigSurface::from_fn(|x, _| (x * a.tan()).max(0.0), 0.12, -0.1, 0.6, "face");
        let normal = [-a.sin(), a.cos()];
        let p = [0.2 - 0.02 * normal[0], 0.2 * a.tan() - 0.02 * normal[1]];
        assert_relative_eq!(s.cut_thickness(p, normal), 0.02, epsilon = 2e-5);
        // Above the surface: nothing to cut.
        assert_eq!(s.cut_thickness([0.1, 0.5], normal), 0.0);
    }

    #[test]
    fn path_integral_matches_the_area_between_path_and_surface() {
        // A circular arc under a flat top: the region between a chord-like
        // path and the surface y = 0.1 has a closed-form area.
        let s = DigSurface::from_fn(|_, _| 0.1, 0.12, -0.5, 0.5, "flat");
        // Path: the lower arc of a circle of radius r centred k above the top,
        // travelled left to right (counter-clockwise in angle).
        let (r, k): (f64, f64) = (0.3, 0.2);
        let (phi1, phi2) = (PI + (k / r).asin(), 2.0 * PI - (k / r).asin());
        let n = 4000;
        let mut area = 0.0;
        let mut prev: Option<([f64; 2], f64)> = None;
        for i in 0..=n {
            let phi = phi1 + (phi2 - phi1) * i as f64 / n as f64;
            let p = [r * phi.cos(), 0.1 + k + r * phi.sin()];
            let left = [-phi.cos(), -phi.sin()]; // left of (−sin φ, cos φ)
            let c = swept_width(s.cut_thickness(p, left), 1.0 / r);
            if let Some((q, c0)) = prev {
                let ds = (p[0] - q[0]).hypot(p[1] - q[1]);
                area += 0.5 * (c + c0) * ds;
            }
            prev = Some((p, c));
        }
        // Circular segment below the chord: r²(θ − sin θ)/2.
        let theta = phi2 - phi1;
        let segment = 0.5 * r * r * (theta - theta.sin());
        // With the curvature term this deep cut (10 cm under a 0.3 m radius,
        // where ∫c ds alone over-counts by 9 %) comes out exact.
        assert_relative_eq!(area, segment, max_relative = 1e-4);
    }

    #[test]
    fn synthetic_piles_start_at_the_toe_and_reach_the_face_height() {
        for shape in PileShape::ALL {
            let s = DigSurface::from_shape(shape, 0.12);
            assert!(s.height(-0.05).abs() < 1e-9, "{shape:?}");
            let h = PileParams::paper_model().scale * PileParams::default().face_height_m;
            assert_relative_eq!(s.top(), h, max_relative = 1e-3);
        }
    }
}
