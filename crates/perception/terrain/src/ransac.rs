//! Plane fitting by RANSAC (Fischler & Bolles 1981) with least-squares
//! refinement — the tool behind the floor estimate of [`crate::estimate_tilt`]
//! (SPEC §4.1: estimate the α, β of [RS eq. 11]–[RS eq. 12] from the floor).
//!
//! 1. Hypotheses: planes through three points drawn at random (seeded
//!    ChaCha8) from at most [`RansacParams::max_scored_points`] points; each is
//!    scored by its number of inliers, points within
//!    [`RansacParams::inlier_threshold_m`] of it. A hypothesis whose normal is
//!    further than [`RansacParams::max_tilt_rad`] from the z axis is not a
//!    candidate (this keeps a pile face from being taken for the floor).
//! 2. Iterations from the desired confidence p: after a best inlier ratio w,
//!    `k = ln(1 − p) / ln(1 − w³)` draws suffice to have drawn one all-inlier
//!    triple with probability p; k is updated as w improves and capped by
//!    [`RansacParams::max_iterations`].
//! 3. Refinement: the inliers of the best hypothesis (among *all* points) are
//!    fitted by orthogonal least squares — the plane through their centroid
//!    whose normal is the eigenvector of the smallest eigenvalue of their
//!    covariance, which minimises Σ (n·p − d)² — then inliers are collected
//!    again and the fit repeated ([`RansacParams::refine_rounds`] times).

use autoshovel_point_cloud::simd::Isa;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use rand::seq::index::sample;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::{Result, SurfaceError};

/// A plane `n · p = d` with unit normal `n` pointing up (`n_z ≥ 0`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Plane {
    /// Unit normal, `n_z ≥ 0`.
    pub normal: [f64; 3],
    /// Offset d (m): signed distance of the plane from the origin along `normal`.
    pub offset_m: f64,
}

impl Plane {
    /// The plane through a point with a normal (any length, flipped up).
    /// `None` for a zero or non-finite normal.
    pub fn from_point_normal(point: [f64; 3], normal: [f64; 3]) -> Option<Self> {
        let n = Vector3::from(normal);
        let len = n.norm();
        if !(len.is_finite() && len > 0.0) {
            return None;
        }
        let mut n = n / len;
        if n.z < 0.0 {
            n = -n;
        }
        Some(Self {
            normal: n.into(),
            offset_m: n.dot(&Vector3::from(point)),
        })
    }

    /// Signed distance of a point (m), positive on the side the normal points to.
    pub fn signed_distance(&self, p: [f64; 3]) -> f64 {
        self.normal[0] * p[0] + self.normal[1] * p[1] + self.normal[2] * p[2] - self.offset_m
    }

    /// Angle between the normal and the z axis (rad).
    pub fn tilt_rad(&self) -> f64 {
        self.normal[2].clamp(-1.0, 1.0).acos()
    }
}

/// Parameters of [`ransac_plane`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct RansacParams {
    /// Largest distance of an inlier from the plane (m). Default 0.05 m: a
    /// few times the 2 cm range noise of a mine-scale scan; use ~2 mm for the
    /// paper's 1:30 model.
    pub inlier_threshold_m: f64,
    /// Probability of having drawn at least one all-inlier triple, in (0, 1).
    /// Default 0.999.
    pub confidence: f64,
    /// Cap on hypotheses drawn. Default 2000.
    pub max_iterations: usize,
    /// Hypotheses are drawn from and scored on a random subset of at most
    /// this many points (refinement uses all of them). Default 20 000.
    pub max_scored_points: usize,
    /// Largest angle between a candidate's normal and the z axis (rad);
    /// `π/2` accepts any plane. Default 30°.
    pub max_tilt_rad: f64,
    /// Least-squares refinement rounds on the inliers. Default 2.
    pub refine_rounds: usize,
    /// Seed of the ChaCha8 generator. Default 1.
    pub seed: u64,
}

impl Default for RansacParams {
    fn default() -> Self {
        Self {
            inlier_threshold_m: 0.05,
            confidence: 0.999,
            max_iterations: 2000,
            max_scored_points: 20_000,
            max_tilt_rad: 30f64.to_radians(),
            refine_rounds: 2,
            seed: 1,
        }
    }
}

impl RansacParams {
    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value: f64, expected| {
            Err(SurfaceError::BadParameter {
                name,
                value,
                expected,
            })
        };
        if !(self.inlier_threshold_m.is_finite() && self.inlier_threshold_m > 0.0) {
            return bad(
                "RansacParams.inlier_threshold_m",
                self.inlier_threshold_m,
                "a distance > 0 [m]",
            );
        }
        if !(self.confidence > 0.0 && self.confidence < 1.0) {
            return bad(
                "RansacParams.confidence",
                self.confidence,
                "a value in (0, 1)",
            );
        }
        if self.max_iterations == 0 {
            return bad("RansacParams.max_iterations", 0.0, "at least 1");
        }
        if self.max_scored_points < 3 {
            return bad(
                "RansacParams.max_scored_points",
                self.max_scored_points as f64,
                "at least 3",
            );
        }
        if !(self.max_tilt_rad > 0.0 && self.max_tilt_rad <= std::f64::consts::FRAC_PI_2) {
            return bad(
                "RansacParams.max_tilt_rad",
                self.max_tilt_rad,
                "an angle in (0, π/2] [rad]",
            );
        }
        Ok(())
    }
}

/// The result of [`ransac_plane`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneFit {
    /// The refined plane.
    pub plane: Plane,
    /// Indices of the inliers of the refined plane, ascending.
    pub inliers: Vec<usize>,
    /// Root-mean-square distance of the inliers from the plane (m).
    pub rms_m: f64,
    /// Hypotheses drawn.
    pub iterations: usize,
}

/// Fit the dominant plane of `points` by RANSAC and least-squares refinement
/// (see the module docs). Same seed, same result.
pub fn ransac_plane(points: &[[f64; 3]], params: &RansacParams) -> Result<PlaneFit> {
    params.validate()?;
    if points.len() < 3 {
        return Err(SurfaceError::TooFewPoints {
            stage: "plane RANSAC",
            points: points.len(),
            required: 3,
            hint: "",
        });
    }
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let scored: Vec<[f64; 3]> = if points.len() > params.max_scored_points {
        let mut idx = sample(&mut rng, points.len(), params.max_scored_points).into_vec();
        idx.sort_unstable();
        idx.into_iter().map(|i| points[i]).collect()
    } else {
        points.to_vec()
    };
    let n = scored.len();
    let min_nz = params.max_tilt_rad.cos() - 1e-12;
    let threshold = params.inlier_threshold_m;
    let log_fail = (1.0 - params.confidence).ln();

    let mut best: Option<(Plane, usize)> = None;
    let mut needed = params.max_iterations;
    let mut iterations = 0;
    while iterations < needed {
        iterations += 1;
        let (i, j, k) = distinct_triple(&mut rng, n);
        let (a, b, c) = (
            Vector3::from(scored[i]),
            Vector3::from(scored[j]),
            Vector3::from(scored[k]),
        );
        let cross = (b - a).cross(&(c - a));
        let scale = (b - a).norm() * (c - a).norm();
        if cross.norm().is_nan() || cross.norm() <= 1e-9 * scale {
            continue; // collinear or coincident: no plane
        }
        let Some(plane) = Plane::from_point_normal(a.into(), cross.into()) else {
            continue;
        };
        if plane.normal[2] < min_nz {
            continue;
        }
        let count = scored
            .iter()
            .filter(|p| plane.signed_distance(**p).abs() <= threshold)
            .count();
        if !matches!(best, Some((_, c)) if c >= count) {
            best = Some((plane, count));
            let w = count as f64 / n as f64;
            let p_all = w * w * w;
            let k = if p_all >= 1.0 {
                1.0
            } else {
                (log_fail / (1.0 - p_all).ln()).ceil()
            };
            if k.is_finite() && k >= 0.0 {
                needed = needed.min((k as usize).max(1));
            }
        }
    }
    let Some((mut plane, _)) = best else {
        return Err(SurfaceError::NoFloor {
            inliers: 0,
            candidates: points.len(),
            required: 3,
            max_tilt_deg: params.max_tilt_rad.to_degrees(),
        });
    };

    let mut inliers = inliers_of(points, &plane, threshold);
    for _ in 0..params.refine_rounds {
        let Some(refined) = least_squares_plane(points, &inliers) else {
            break;
        };
        if refined.normal[2] < min_nz {
            break;
        }
        plane = refined;
        inliers = inliers_of(points, &plane, threshold);
    }
    let rms_m = if inliers.is_empty() {
        0.0
    } else {
        (inliers
            .iter()
            .map(|&i| plane.signed_distance(points[i]).powi(2))
            .sum::<f64>()
            / inliers.len() as f64)
            .sqrt()
    };
    Ok(PlaneFit {
        plane,
        inliers,
        rms_m,
        iterations,
    })
}

/// Orthogonal least-squares plane through the points at `indices`: through
/// their centroid, normal = eigenvector of the smallest covariance eigenvalue.
/// `None` for fewer than three points.
pub fn least_squares_plane(points: &[[f64; 3]], indices: &[usize]) -> Option<Plane> {
    plane_through(indices, |i| points[i])
}

/// [`least_squares_plane`] through the points `at(i)` for `i` in `indices`
/// (a caller whose points are stored otherwise: as f32, converted exactly).
pub(crate) fn plane_through(indices: &[usize], at: impl Fn(usize) -> [f64; 3]) -> Option<Plane> {
    if indices.len() < 3 {
        return None;
    }
    let m = indices.len() as f64;
    let centroid = indices
        .iter()
        .fold(Vector3::zeros(), |s, &i| s + Vector3::from(at(i)))
        / m;
    let cov = indices.iter().fold(Matrix3::zeros(), |s, &i| {
        let d = Vector3::from(at(i)) - centroid;
        s + d * d.transpose()
    }) / m;
    let eig = SymmetricEigen::new(cov);
    let k = eig.eigenvalues.imin();
    Plane::from_point_normal(
        centroid.into(),
        eig.eigenvectors.column(k).into_owned().into(),
    )
}

/// Indices of the points within `threshold` of `plane`, ascending.
pub(crate) fn inliers_of(points: &[[f64; 3]], plane: &Plane, threshold: f64) -> Vec<usize> {
    use rayon::prelude::*;
    const PART: usize = 1 << 16;
    if points.len() <= PART {
        return inliers_from(points, 0, plane, threshold);
    }
    let parts: Vec<Vec<usize>> = points
        .par_chunks(PART)
        .enumerate()
        .map(|(j, part)| inliers_from(part, j * PART, plane, threshold))
        .collect();
    parts.concat()
}

/// `first + i` for each point `i` of `points` within `threshold` of
/// `plane`, ascending. Every index is written and the count moves on by
/// the test, with no branch on it: a floor's inliers and the pile's points
/// come mixed, and a filter's branch mispredicted on them (the
/// hypotheses' inliers were most of the floor search of a 100 k-point frame).
fn inliers_from(points: &[[f64; 3]], first: usize, plane: &Plane, threshold: f64) -> Vec<usize> {
    inliers_from_on(Isa::best(), points, first, plane, threshold)
}

/// [`inliers_from`] on the path of `isa` (AVX-512: `wide::avx512`).
fn inliers_from_on(
    isa: Isa,
    points: &[[f64; 3]],
    first: usize,
    plane: &Plane,
    threshold: f64,
) -> Vec<usize> {
    #[cfg(target_arch = "x86_64")]
    if let Some(t) = isa.avx512() {
        // SAFETY: `t` proves AVX-512F and POPCNT, the kernel's requirements.
        return unsafe {
            crate::wide::avx512::inliers(
                t,
                points,
                first,
                (plane.normal, plane.offset_m),
                threshold,
            )
        };
    }
    let _ = isa;
    let mut kept = vec![0; points.len()];
    let mut count = 0;
    for (i, p) in points.iter().enumerate() {
        kept[count] = first + i;
        count += usize::from(plane.signed_distance(*p).abs() <= threshold);
    }
    kept.truncate(count);
    kept
}

fn distinct_triple(rng: &mut ChaCha8Rng, n: usize) -> (usize, usize, usize) {
    let i = rng.gen_range(0..n);
    let mut j = rng.gen_range(0..n - 1);
    if j >= i {
        j += 1;
    }
    let (lo, hi) = if i < j { (i, j) } else { (j, i) };
    let mut k = rng.gen_range(0..n - 2);
    if k >= lo {
        k += 1;
    }
    if k >= hi {
        k += 1;
    }
    (i, j, k)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand_distr::{Distribution, Normal};

    /// Points near a tilted plane, some exactly a threshold off it (where
    /// `<=` decides), some not numbers, in every count of a step's tail.
    fn near_a_plane(n: usize, seed: u64) -> (Vec<[f64; 3]>, Plane) {
        let plane = Plane::from_point_normal([0.0, 0.0, 1.5], [0.1, -0.05, 1.0]).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let points = (0..n)
            .map(|i| match i % 7 {
                // On the plane's axis, exactly 0.05 above or below it.
                0 => [0.0, 0.0, if i % 2 == 0 { 1.55 } else { 1.45 }],
                1 if i % 3 == 0 => [f64::NAN, 1.0, 2.0],
                _ => {
                    let (x, y) = (rng.gen_range(-5.0..5.0), rng.gen_range(-5.0..5.0));
                    [x, y, 1.5 - 0.1 * x + 0.05 * y + rng.gen_range(-0.2..0.2)]
                }
            })
            .collect();
        (points, plane)
    }

    #[test]
    fn inliers_are_the_same_on_every_path() {
        // The plane's normal is unit, so the points 0.05 off along z are a
        // little less than 0.05 off it: the threshold is set to their own
        // distance, to be met exactly.
        for n in (0..=40).chain([1000, 4099]) {
            let (points, plane) = near_a_plane(n, n as u64);
            let on_edge = plane.signed_distance([0.0, 0.0, 1.55]).abs();
            for threshold in [0.05, on_edge] {
                let portable = inliers_from_on(Isa::PORTABLE, &points, 3, &plane, threshold);
                assert!(portable.iter().all(|&i| i >= 3 && i < n + 3));
                for isa in Isa::available() {
                    let got = inliers_from_on(isa, &points, 3, &plane, threshold);
                    assert_eq!(got, portable, "{isa:?}, {n} points, threshold {threshold}");
                }
            }
            // The edge case occurs: points exactly at the threshold kept.
            if n > 0 {
                let kept = inliers_from_on(Isa::PORTABLE, &points, 0, &plane, on_edge);
                assert!(kept.contains(&0), "{n} points");
            }
        }
    }

    /// Points on z = 0.1 x − 0.05 y + 2 with noise, plus gross outliers above.
    fn noisy_plane(n: usize, outliers: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.01).unwrap();
        let mut pts: Vec<[f64; 3]> = (0..n)
            .map(|_| {
                let x = rng.gen_range(-10.0..10.0);
                let y = rng.gen_range(-10.0..10.0);
                [x, y, 0.1 * x - 0.05 * y + 2.0 + noise.sample(&mut rng)]
            })
            .collect();
        for _ in 0..outliers {
            pts.push([
                rng.gen_range(-10.0..10.0),
                rng.gen_range(-10.0..10.0),
                rng.gen_range(3.0..8.0),
            ]);
        }
        pts
    }

    #[test]
    fn exact_plane_through_three_points() {
        let pts = [[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        let fit = ransac_plane(&pts, &RansacParams::default()).unwrap();
        assert_relative_eq!(fit.plane.normal[2], 1.0, epsilon = 1e-12);
        assert_relative_eq!(fit.plane.offset_m, 1.0, epsilon = 1e-12);
        assert_eq!(fit.inliers, vec![0, 1, 2]);
    }

    #[test]
    fn recovers_a_tilted_plane_among_40_percent_outliers() {
        let pts = noisy_plane(3000, 2000, 7);
        let fit = ransac_plane(&pts, &RansacParams::default()).unwrap();
        let expected = Vector3::new(-0.1, 0.05, 1.0).normalize();
        let got = Vector3::from(fit.plane.normal);
        assert!(got.angle(&expected).to_degrees() < 0.05, "{got:?}");
        assert_relative_eq!(fit.plane.offset_m, 2.0 * expected.z, epsilon = 2e-3);
        assert!(fit.inliers.len() >= 2990 && fit.inliers.len() <= 3005);
        assert!(fit.rms_m < 0.012);
        assert!(fit.iterations < 100, "adaptive count: {}", fit.iterations);
    }

    #[test]
    fn same_seed_same_plane() {
        let pts = noisy_plane(50_000, 20_000, 3);
        let p = RansacParams::default();
        let a = ransac_plane(&pts, &p).unwrap();
        let b = ransac_plane(&pts, &p).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn steep_planes_are_not_candidates() {
        // A wall x = 1 only: no plane within 30° of horizontal.
        let pts: Vec<[f64; 3]> = (0..100)
            .map(|i| [1.0, (i % 10) as f64, (i / 10) as f64])
            .collect();
        let err = ransac_plane(&pts, &RansacParams::default()).unwrap_err();
        assert!(
            matches!(err, SurfaceError::NoFloor { inliers: 0, .. }),
            "{err}"
        );
    }

    #[test]
    fn bad_parameters_are_named() {
        let p = RansacParams {
            confidence: 1.0,
            ..RansacParams::default()
        };
        let err = ransac_plane(&[[0.0; 3]; 3], &p).unwrap_err();
        assert!(err.to_string().contains("RansacParams.confidence"), "{err}");
    }
}
