//! Tracking geometry (electric-shovel paper [W eq. 21]–[W eq. 22]): the preview point C
//! at distance L ahead of the centroid O in the direction of motion, A the
//! path point nearest O, B the path point nearest C, the preview deviation d
//! (distance of C from the line AB) and the centroid deviation d0 = |O − A|.
//!
//! As SPEC §3 asks, both deviations are **signed**, positive when the point
//! lies left of the path (seen in the direction of travel): the paper's
//! absolute values cannot tell which way to steer. On a reverse leg "ahead"
//! is behind the machine, so C lies behind it, and left is the left of the
//! motion. [W eq. 21] writes C with the north-clockwise RTK heading ϕ; here the
//! pose is already in the library's frame (θ = π/2 − ϕ converted at the sensor).

use autoshovel_core::{arc_lengths, heading_vec, segment_nearest, Pose2, Vec2};
use autoshovel_walk_planner::Direction;

/// One leg of a reference path, as the tracker sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct RefLeg {
    /// Forward or reverse.
    pub direction: Direction,
    /// Path points in travel order (m).
    pub points: Vec<Vec2>,
    /// Arc length at each point (m).
    pub s: Vec<f64>,
    /// Required machine heading at the end (rad).
    pub end_heading_rad: f64,
}

/// Why a path cannot be tracked.
#[derive(Debug, Clone, PartialEq)]
pub enum PathFault {
    /// Fewer than two points.
    TooFewPoints(usize),
    /// Two consecutive points coincide (index of the second).
    RepeatedPoint(usize),
    /// A coordinate is not finite (index).
    NotFinite(usize),
}

impl std::fmt::Display for PathFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PathFault::TooFewPoints(n) => write!(f, "has {n} points; a path needs at least 2"),
            PathFault::RepeatedPoint(i) => write!(
                f,
                "repeats point {} at index {i} (0-based); remove duplicates",
                i - 1
            ),
            PathFault::NotFinite(i) => {
                write!(f, "has a non-finite coordinate at index {i} (0-based)")
            }
        }
    }
}

impl RefLeg {
    /// A checked leg; the end heading defaults to the last segment's machine heading.
    pub fn new(
        direction: Direction,
        points: Vec<Vec2>,
        end_heading_rad: Option<f64>,
    ) -> Result<Self, PathFault> {
        if points.len() < 2 {
            return Err(PathFault::TooFewPoints(points.len()));
        }
        for (i, p) in points.iter().enumerate() {
            if !(p.x.is_finite() && p.y.is_finite()) {
                return Err(PathFault::NotFinite(i));
            }
            if i > 0 && (p - points[i - 1]).norm() < 1e-9 {
                return Err(PathFault::RepeatedPoint(i));
            }
        }
        let n = points.len();
        let last = points[n - 1] - points[n - 2];
        let motion = last.y.atan2(last.x);
        let end = end_heading_rad.unwrap_or(match direction {
            Direction::Forward => motion,
            Direction::Reverse => autoshovel_core::wrap_angle(motion + std::f64::consts::PI),
        });
        let s = arc_lengths(&points);
        Ok(Self {
            direction,
            points,
            s,
            end_heading_rad: end,
        })
    }

    /// Length (m).
    pub fn length_m(&self) -> f64 {
        *self.s.last().unwrap_or(&0.0)
    }

    /// Nearest point to `p` among segments whose arc length lies in
    /// [s_lo, s_hi]: (point, arc length, unit tangent of its segment).
    pub fn nearest(&self, p: Vec2, s_lo: f64, s_hi: f64) -> (Vec2, f64, Vec2) {
        let mut best = (
            self.points[0],
            0.0,
            (self.points[1] - self.points[0]).normalize(),
        );
        let mut best_d2 = f64::INFINITY;
        for i in 0..self.points.len() - 1 {
            if self.s[i + 1] < s_lo || self.s[i] > s_hi {
                continue;
            }
            let (a, b) = (self.points[i], self.points[i + 1]);
            let (q, t) = segment_nearest(p, a, b);
            let d2 = (p - q).norm_squared();
            if d2 < best_d2 {
                best_d2 = d2;
                best = (
                    q,
                    self.s[i] + t * (self.s[i + 1] - self.s[i]),
                    (b - a).normalize(),
                );
            }
        }
        best
    }

    /// Signed curvature κ of the leg at arc length `s`, positive turning
    /// left in travel order (1/m): the turn between the segments at
    /// `s − window_m` and `s + window_m`, over the arc between their
    /// midpoints (0 on a straight leg, 1/R on an arc of radius R sampled
    /// finer than the window).
    pub fn curvature_at(&self, s: f64, window_m: f64) -> f64 {
        let (i, j) = (self.segment_at(s - window_m), self.segment_at(s + window_m));
        if i == j {
            return 0.0;
        }
        let dir = |k: usize| (self.points[k + 1] - self.points[k]).normalize();
        let (t0, t1) = (dir(i), dir(j));
        let mid = |k: usize| 0.5 * (self.s[k] + self.s[k + 1]);
        (t0.x * t1.y - t0.y * t1.x).atan2(t0.dot(&t1)) / (mid(j) - mid(i))
    }

    /// Index of the segment holding arc length `s` (clamped to the leg).
    fn segment_at(&self, s: f64) -> usize {
        let s = s.clamp(0.0, self.length_m());
        match self.s.binary_search_by(|v| v.total_cmp(&s)) {
            Ok(i) => i.min(self.points.len() - 2),
            Err(i) => i.saturating_sub(1).min(self.points.len() - 2),
        }
    }

    /// The point at arc length `s` (clamped to the leg).
    pub fn point_at(&self, s: f64) -> (Vec2, Vec2) {
        let s = s.clamp(0.0, self.length_m());
        let i = self.segment_at(s);
        let (a, b) = (self.points[i], self.points[i + 1]);
        let t = ((s - self.s[i]) / (self.s[i + 1] - self.s[i])).clamp(0.0, 1.0);
        (a + (b - a) * t, (b - a).normalize())
    }
}

/// The deviations of [W eq. 21]–[W eq. 22] (signed, left positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviations {
    /// Preview deviation d: signed distance of C from the line AB (m).
    pub d_m: f64,
    /// Centroid deviation d0: signed |O − A| (m).
    pub d0_m: f64,
    /// Arc length of A along the leg (m).
    pub s_a_m: f64,
    /// Heading of motion minus the path's tangent at A (rad).
    pub heading_error_rad: f64,
    /// The preview point C.
    pub c: Vec2,
    /// A.
    pub a: Vec2,
    /// B.
    pub b: Vec2,
}

fn cross(u: Vec2, v: Vec2) -> f64 {
    u.x * v.y - u.y * v.x
}

/// How far back and ahead of the last A the nearest-point search looks (m).
pub const SEARCH_BACK_M: f64 = 2.0;
/// See [`SEARCH_BACK_M`].
pub const SEARCH_AHEAD_M: f64 = 10.0;

/// Deviations of `pose` (centroid, crawler heading) from `leg` with preview
/// distance `preview_m`: the preview point C = O + L·(direction of motion)
/// [W eq. 21], the preview deviation d and the centroid deviation d0
/// [W eq. 22], both signed. `s_hint` is the previous A's arc length (None:
/// search the whole leg).
pub fn deviations(leg: &RefLeg, pose: Pose2, preview_m: f64, s_hint: Option<f64>) -> Deviations {
    let o = pose.position();
    let motion = heading_vec(leg.direction.motion_heading(pose.theta));
    // C = O + L·(direction of motion) [W eq. 21]
    let c = o + motion * preview_m;
    let (lo, hi) = match s_hint {
        Some(s) => (s - SEARCH_BACK_M, s + SEARCH_AHEAD_M),
        None => (f64::NEG_INFINITY, f64::INFINITY),
    };
    let (a, s_a, t_a) = leg.nearest(o, lo, hi);
    let (mut b, s_b, _) = leg.nearest(c, s_a - SEARCH_BACK_M, s_a + preview_m + SEARCH_AHEAD_M);
    // Near the end the preview point runs past the path: measure it against
    // the path continued along its last tangent, not against the end point,
    // so the machine arrives aligned with the last segment.
    if s_b >= leg.length_m() - 1e-9 {
        let (end, t_end) = leg.point_at(leg.length_m());
        b = end + t_end * (c - end).dot(&t_end).max(0.0);
    }
    // d0 = |O − A|, signed [W eq. 22]
    let d0 = cross(t_a, o - a).signum() * (o - a).norm();
    let ab = b - a;
    // d = ((B − A) × (C − A)) / |B − A|, signed [W eq. 22]
    let d = if ab.norm() > 1e-9 {
        cross(ab, c - a) / ab.norm()
    } else {
        cross(t_a, c - a)
    };
    let heading_error = autoshovel_core::angle_diff(motion.y.atan2(motion.x), t_a.y.atan2(t_a.x));
    Deviations {
        d_m: d,
        d0_m: d0,
        s_a_m: s_a,
        heading_error_rad: heading_error,
        c,
        a,
        b,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn diagonal() -> RefLeg {
        RefLeg::new(
            Direction::Forward,
            vec![Vec2::new(0.0, 0.0), Vec2::new(30.0, 30.0)],
            None,
        )
        .unwrap()
    }

    #[test]
    fn fig9_starts_have_the_closed_form_deviations() {
        // Fig. 9a: (2, −2) is 2√2 m right of the line y = x; heading π/4 is parallel, so d = d0.
        let dv = deviations(
            &diagonal(),
            Pose2::new(2.0, -2.0, std::f64::consts::FRAC_PI_4),
            1.0,
            None,
        );
        assert_relative_eq!(dv.d0_m, -8f64.sqrt(), epsilon = 1e-12);
        assert_relative_eq!(dv.d_m, -8f64.sqrt(), epsilon = 1e-12);
        // Fig. 9b: (0, 5) is 5/√2 m left.
        let dv = deviations(
            &diagonal(),
            Pose2::new(0.0, 5.0, std::f64::consts::FRAC_PI_4),
            1.0,
            None,
        );
        assert_relative_eq!(dv.d0_m, 5.0 / 2f64.sqrt(), epsilon = 1e-12);
    }

    #[test]
    fn heading_towards_the_path_shrinks_the_preview_deviation() {
        let leg = RefLeg::new(
            Direction::Forward,
            vec![Vec2::new(0.0, 0.0), Vec2::new(50.0, 0.0)],
            None,
        )
        .unwrap();
        // 1 m left of the x axis, heading 30° towards it: C is 1 − L sin 30° left.
        let dv = deviations(&leg, Pose2::new(5.0, 1.0, -30f64.to_radians()), 1.5, None);
        assert_relative_eq!(dv.d0_m, 1.0, epsilon = 1e-12);
        assert_relative_eq!(dv.d_m, 1.0 - 1.5 * 0.5, epsilon = 1e-12);
        assert_relative_eq!(dv.heading_error_rad, -30f64.to_radians(), epsilon = 1e-12);
    }

    #[test]
    fn reversing_puts_the_preview_point_behind_and_keeps_left_positive() {
        // Reverse leg travelled towards +x; the machine faces −x.
        let leg = RefLeg::new(
            Direction::Reverse,
            vec![Vec2::new(0.0, 0.0), Vec2::new(50.0, 0.0)],
            None,
        )
        .unwrap();
        assert_relative_eq!(
            leg.end_heading_rad.abs(),
            std::f64::consts::PI,
            epsilon = 1e-12
        );
        let dv = deviations(&leg, Pose2::new(10.0, 0.5, std::f64::consts::PI), 2.0, None);
        assert_relative_eq!(dv.c, Vec2::new(12.0, 0.5), epsilon = 1e-12); // behind the machine = ahead in motion
        assert_relative_eq!(dv.d0_m, 0.5, epsilon = 1e-12); // left of the motion
        assert_relative_eq!(dv.heading_error_rad, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn bad_paths_are_refused() {
        assert_eq!(
            RefLeg::new(Direction::Forward, vec![Vec2::zeros()], None).unwrap_err(),
            PathFault::TooFewPoints(1)
        );
        assert_eq!(
            RefLeg::new(Direction::Forward, vec![Vec2::zeros(), Vec2::zeros()], None).unwrap_err(),
            PathFault::RepeatedPoint(1)
        );
        assert_eq!(
            RefLeg::new(
                Direction::Forward,
                vec![Vec2::zeros(), Vec2::new(f64::NAN, 1.0)],
                None
            )
            .unwrap_err(),
            PathFault::NotFinite(1)
        );
    }
}
