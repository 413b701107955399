//! The material surface `z = f(x, y)` (rope-shovel paper §3.2, [RS eq. 21]): a
//! bivariate polynomial fitted by least squares to the 8 × 8 grid samples of
//! [`crate::sample_grid`], accepted only when R² > 0.95.
//!
//! - **Model.** `f(x, y) = Σ_{i+j ≤ d} c_ij u^i v^j` of total degree
//!   d ∈ 1..=5, in the normalised coordinates `u = (x − x_c)/h_x`,
//!   `v = (y − y_c)/h_y` (centre and half-width of the grid extent, so u, v ∈
//!   [−1, 1] and the design matrix stays well conditioned). The coefficients
//!   in plain x, y ([`SurfaceFit::coefficients_xy`]) are the binomial
//!   expansion of these.
//! - **Least squares** by the SVD of the design matrix A (nalgebra), which
//!   also gives the numerical rank: a degree whose terms the samples do not
//!   determine (rank < terms) is not a candidate.
//! - **Degree** (the paper says only "surface fitting"; SPEC: "degree chosen by
//!   the fit"): the degree with the smallest leave-one-out cross-validation
//!   error, PRESS = Σ (e_i / (1 − h_ii))², with h_ii the leverages (the
//!   diagonal of the hat matrix `U Uᵀ`), computed exactly from one fit. Unlike
//!   R², which can only grow with the degree, PRESS grows again once extra
//!   terms fit the noise of 64 samples; a higher degree must lower it by more
//!   than [`FitParams::press_tolerance`] (and its leave-one-out RMS by more
//!   than 10⁻⁶ (1 + max |z|), the rounding of f32 coordinates) to be chosen.
//!   Degrees need at least two samples more than terms.
//! - **Goodness of fit.** `R² = 1 − SS_res/SS_tot` on the samples (the
//!   paper's criterion), adjusted `R̄² = 1 − (1 − R²)(n − 1)/(n − p)`, RMS
//!   residual, the leave-one-out RMS, and R² against every cloud point inside
//!   the grid extent (not only the 64 samples). A fit with
//!   `R² ≤ FitParams::r2_threshold` (default 0.95) is refused with
//!   [`SurfaceError::PoorFit`]. A set of samples of equal height is fitted
//!   exactly by the constant term; its R² is taken as 1.

use autoshovel_point_cloud::PointCloud;
use nalgebra::{DMatrix, DVector};

use crate::error::{Result, SurfaceError};
use crate::sample::{sample_grid, Extent, GridSample, SampleParams};

/// Parameters of [`fit_surface`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct FitParams {
    /// The 8 × 8 sample grid.
    pub sampling: SampleParams,
    /// A fixed total degree, or `None` to choose it by leave-one-out
    /// cross-validation. Default `None`.
    pub degree: Option<usize>,
    /// Highest total degree tried, 1..=8. Default 5 (21 terms for 64 samples).
    pub max_degree: usize,
    /// Relative drop of PRESS a higher degree must bring to be chosen, ≥ 0.
    /// Default 0.02.
    pub press_tolerance: f64,
    /// Refuse fits with R² at or below this; `None` accepts any fit.
    /// Default `Some(0.95)` (paper §3.2: R² > 0.95).
    pub r2_threshold: Option<f64>,
}

impl Default for FitParams {
    fn default() -> Self {
        Self {
            sampling: SampleParams::default(),
            degree: None,
            max_degree: 5,
            press_tolerance: 0.02,
            r2_threshold: Some(0.95),
        }
    }
}

impl FitParams {
    /// Check the ranges once, at the edge.
    pub fn validate(&self) -> Result<()> {
        self.sampling.validate()?;
        if !(1..=8).contains(&self.max_degree) {
            return Err(SurfaceError::BadParameter {
                name: "FitParams.max_degree",
                value: self.max_degree as f64,
                expected: "a degree in 1..=8",
            });
        }
        if let Some(d) = self.degree {
            if !(1..=8).contains(&d) {
                return Err(SurfaceError::BadParameter {
                    name: "FitParams.degree",
                    value: d as f64,
                    expected: "a degree in 1..=8",
                });
            }
        }
        if !(self.press_tolerance >= 0.0 && self.press_tolerance.is_finite()) {
            return Err(SurfaceError::BadParameter {
                name: "FitParams.press_tolerance",
                value: self.press_tolerance,
                expected: "a share >= 0",
            });
        }
        if let Some(t) = self.r2_threshold {
            if !(t < 1.0 && t.is_finite()) {
                return Err(SurfaceError::BadParameter {
                    name: "FitParams.r2_threshold",
                    value: t,
                    expected: "a value below 1 (or None to accept any fit)",
                });
            }
        }
        Ok(())
    }
}

/// One term `coefficient · x^x_power · y^y_power` of a polynomial.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Term {
    /// Power of x (or u).
    pub x_power: usize,
    /// Power of y (or v).
    pub y_power: usize,
    /// Coefficient [m / m^(x_power + y_power)] in x, y; (m) in u, v.
    pub coefficient: f64,
}

/// How one candidate degree did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DegreeScore {
    /// Total degree.
    pub degree: usize,
    /// Terms, (d + 1)(d + 2)/2.
    pub terms: usize,
    /// R² on the samples.
    pub r2: f64,
    /// Adjusted R² on the samples.
    pub adjusted_r2: f64,
    /// Leave-one-out RMS prediction error, sqrt(PRESS/n) (m).
    pub loo_rms_m: f64,
}

/// A fitted surface `z = f(x, y)` and how well it fits.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceFit {
    /// Total degree of the polynomial.
    pub degree: usize,
    /// The grid extent; the fit is meant for (x, y) inside it.
    pub extent: Extent,
    /// Centre (x_c, y_c) of the normalisation (m).
    pub centre_m: [f64; 2],
    /// Half-widths (h_x, h_y) of the normalisation (m).
    pub half_span_m: [f64; 2],
    /// Coefficients in the normalised u, v (see the module docs).
    pub coefficients: Vec<Term>,
    /// R² on the grid samples (the paper's criterion).
    pub r2: f64,
    /// Adjusted R² on the grid samples.
    pub adjusted_r2: f64,
    /// RMS residual on the grid samples (m).
    pub rms_residual_m: f64,
    /// Leave-one-out RMS prediction error on the samples (m).
    pub loo_rms_m: f64,
    /// The grid samples fitted.
    pub samples: Vec<GridSample>,
    /// Residual `z − f(x, y)` per sample (m), in the order of `samples`.
    pub residuals_m: Vec<f64>,
    /// R² against every cloud point inside the extent.
    pub r2_all_points: f64,
    /// RMS residual against every cloud point inside the extent (m).
    pub rms_all_points_m: f64,
    /// Cloud points inside the extent.
    pub points_in_extent: usize,
    /// Every degree tried, lowest first.
    pub candidates: Vec<DegreeScore>,
}

/// Fit the material surface of a (levelled, filtered) cloud: 8 × 8 grid
/// samples, least-squares polynomial, degree by leave-one-out
/// cross-validation, refusal at R² ≤ threshold (see the module docs).
///
/// ```
/// use autoshovel_point_cloud::PointCloud;
/// use autoshovel_terrain::{fit_surface, FitParams};
/// let mut pts = Vec::new();
/// for i in 0..50 {
///     for j in 0..50 {
///         let (x, y) = (i as f32 * 0.2, j as f32 * 0.2);
///         pts.push([x, y, 1.0 + 0.5 * x - 0.2 * y]);
///     }
/// }
/// let fit = fit_surface(&PointCloud::new(pts), &FitParams::default()).unwrap();
/// assert!(fit.r2 > 0.999_999);
/// assert!((fit.height(3.0, 4.0) - 1.7).abs() < 1e-5);
/// ```
pub fn fit_surface(cloud: &PointCloud, params: &FitParams) -> Result<SurfaceFit> {
    params.validate()?;
    let grid = sample_grid(cloud, &params.sampling)?;
    let mut fit = fit_samples(&grid.samples, grid.extent, params)?;
    let (r2_all, rms_all, inside) = fit.score_points(cloud);
    fit.r2_all_points = r2_all;
    fit.rms_all_points_m = rms_all;
    fit.points_in_extent = inside;
    if let Some(threshold) = params.r2_threshold {
        if fit.r2.is_nan() || fit.r2 <= threshold {
            return Err(SurfaceError::PoorFit {
                r2: fit.r2,
                threshold,
                degree: fit.degree,
                samples: fit.samples.len(),
            });
        }
    }
    Ok(fit)
}

/// Fit samples directly (no threshold check, no cloud score): the least
/// squares and degree choice of [`fit_surface`].
pub fn fit_samples(
    samples: &[GridSample],
    extent: Extent,
    params: &FitParams,
) -> Result<SurfaceFit> {
    params.validate()?;
    let n = samples.len();
    if n < 5 {
        return Err(SurfaceError::TooFewPoints {
            stage: "surface fit",
            points: n,
            required: 5,
            hint: "; the grid samples come from non-empty cells of the 8 × 8 grid",
        });
    }
    let centre = [
        0.5 * (extent.x_min_m + extent.x_max_m),
        0.5 * (extent.y_min_m + extent.y_max_m),
    ];
    let half = [0.5 * extent.x_span_m(), 0.5 * extent.y_span_m()];
    let uv: Vec<[f64; 2]> = samples
        .iter()
        .map(|s| [(s.x_m - centre[0]) / half[0], (s.y_m - centre[1]) / half[1]])
        .collect();
    let z = DVector::from_iterator(n, samples.iter().map(|s| s.z_m));
    let mean = z.mean();
    let ss_tot: f64 = z.iter().map(|v| (v - mean).powi(2)).sum();

    let degrees: Vec<usize> = match params.degree {
        Some(d) => vec![d],
        None => (1..=params.max_degree).collect(),
    };
    let mut candidates = Vec::new();
    let mut fits: Vec<(usize, DVector<f64>, DVector<f64>)> = Vec::new();
    let mut first_failure = None;
    for &d in &degrees {
        let p = term_count(d);
        if n < p + 2 {
            first_failure.get_or_insert(SurfaceError::TooFewPoints {
                stage: "surface fit",
                points: n,
                required: p + 2,
                hint: "; lower FitParams.degree or sample more grid cells",
            });
            continue;
        }
        let a = design(&uv, d);
        let svd = a.clone().svd(true, true);
        let smax = svd.singular_values.max();
        let tol = smax * 1e-10 * n.max(p) as f64;
        let rank = svd.rank(tol);
        if rank < p {
            first_failure.get_or_insert(SurfaceError::DegenerateSamples {
                samples: n,
                rank,
                terms: p,
                degree: d,
            });
            continue;
        }
        let coef = svd.solve(&z, tol).expect("SVD with U and V");
        let u = svd.u.as_ref().expect("computed U");
        let resid = &z - &a * &coef;
        let ss_res: f64 = resid.iter().map(|e| e * e).sum();
        let press: f64 = (0..n)
            .map(|i| {
                let h: f64 = (0..p).map(|k| u[(i, k)].powi(2)).sum();
                (resid[i] / (1.0 - h).max(1e-12)).powi(2)
            })
            .sum();
        let r2 = r_squared(ss_res, ss_tot);
        candidates.push(DegreeScore {
            degree: d,
            terms: p,
            r2,
            adjusted_r2: 1.0 - (1.0 - r2) * (n as f64 - 1.0) / (n - p) as f64,
            loo_rms_m: (press / n as f64).sqrt(),
        });
        fits.push((d, coef, resid));
    }
    if fits.is_empty() {
        return Err(first_failure.expect("a failure for each degree"));
    }
    // Lowest PRESS; a higher degree must beat the current best by the
    // tolerance, and by more than the rounding of f32 coordinates.
    let z_scale = samples.iter().map(|s| s.z_m.abs()).fold(0.0, f64::max);
    let rounding_m = 1e-6 * (1.0 + z_scale);
    let mut best = 0;
    for k in 1..candidates.len() {
        let (b, c) = (candidates[best].loo_rms_m, candidates[k].loo_rms_m);
        if c * c < b * b * (1.0 - params.press_tolerance) && b - c > rounding_m {
            best = k;
        }
    }
    let score = candidates[best];
    let (degree, coef, resid) = fits.swap_remove(best);
    let coefficients = terms(degree)
        .iter()
        .zip(coef.iter())
        .map(|(&(i, j), &c)| Term {
            x_power: i,
            y_power: j,
            coefficient: c,
        })
        .collect();
    let rms = (resid.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    Ok(SurfaceFit {
        degree,
        extent,
        centre_m: centre,
        half_span_m: half,
        coefficients,
        r2: score.r2,
        adjusted_r2: score.adjusted_r2,
        rms_residual_m: rms,
        loo_rms_m: score.loo_rms_m,
        samples: samples.to_vec(),
        residuals_m: resid.iter().copied().collect(),
        r2_all_points: f64::NAN,
        rms_all_points_m: f64::NAN,
        points_in_extent: 0,
        candidates,
    })
}

impl SurfaceFit {
    /// Height of the surface at (x, y) (m).
    pub fn height(&self, x: f64, y: f64) -> f64 {
        let u = (x - self.centre_m[0]) / self.half_span_m[0];
        let v = (y - self.centre_m[1]) / self.half_span_m[1];
        let mut up = [1.0; 9];
        let mut vp = [1.0; 9];
        for k in 1..=self.degree {
            up[k] = up[k - 1] * u;
            vp[k] = vp[k - 1] * v;
        }
        self.coefficients
            .iter()
            .map(|t| t.coefficient * up[t.x_power] * vp[t.y_power])
            .sum()
    }

    /// The coefficients in plain x, y (m): `f = Σ c_ab x^a y^b`, expanded from
    /// the normalised ones by the binomial theorem. Readable as [RS eq. 21], but
    /// worse conditioned: prefer [`SurfaceFit::height`] for evaluation.
    pub fn coefficients_xy(&self) -> Vec<Term> {
        let [cx, cy] = self.centre_m;
        let [hx, hy] = self.half_span_m;
        terms(self.degree)
            .into_iter()
            .map(|(a, b)| {
                let coefficient = self
                    .coefficients
                    .iter()
                    .filter(|t| t.x_power >= a && t.y_power >= b)
                    .map(|t| {
                        let (i, j) = (t.x_power, t.y_power);
                        t.coefficient
                            * binomial(i, a)
                            * binomial(j, b)
                            * (-cx).powi((i - a) as i32)
                            * (-cy).powi((j - b) as i32)
                            / (hx.powi(i as i32) * hy.powi(j as i32))
                    })
                    .sum();
                Term {
                    x_power: a,
                    y_power: b,
                    coefficient,
                }
            })
            .collect()
    }

    /// A height map over the extent: `nx × ny` nodes from edge to edge
    /// (one node sits at the centre).
    pub fn grid(&self, nx: usize, ny: usize) -> HeightMap {
        let e = self.extent;
        let xs = linspace(e.x_min_m, e.x_max_m, nx);
        let ys = linspace(e.y_min_m, e.y_max_m, ny);
        let z_m = ys
            .iter()
            .flat_map(|&y| xs.iter().map(move |&x| (x, y)))
            .map(|(x, y)| self.height(x, y))
            .collect();
        HeightMap { xs, ys, z_m }
    }

    /// R², RMS residual (m) and count of the cloud points inside the extent.
    fn score_points(&self, cloud: &PointCloud) -> (f64, f64, usize) {
        use rayon::prelude::*;
        // The surface's heights in parallel (most of the work), the sums
        // then in the points' order.
        let inside: Vec<Vec<(f64, f64)>> = cloud
            .points
            .par_chunks(1 << 14)
            .map(|chunk| {
                chunk
                    .iter()
                    .filter_map(|p| {
                        let (x, y, z) = (f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
                        self.extent.contains(x, y).then(|| (z, self.height(x, y)))
                    })
                    .collect()
            })
            .collect();
        let (mut n, mut sum, mut sum2, mut ss_res) = (0usize, 0.0, 0.0, 0.0);
        for &(z, h) in inside.iter().flatten() {
            n += 1;
            sum += z;
            sum2 += z * z;
            ss_res += (z - h).powi(2);
        }
        if n == 0 {
            return (f64::NAN, f64::NAN, 0);
        }
        let ss_tot = (sum2 - sum * sum / n as f64).max(0.0);
        (r_squared(ss_res, ss_tot), (ss_res / n as f64).sqrt(), n)
    }
}

/// Heights of a fitted surface on a rectangular grid.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeightMap {
    /// Node x (m), ascending.
    pub xs: Vec<f64>,
    /// Node y (m), ascending.
    pub ys: Vec<f64>,
    /// Heights (m), row by row: `z_m[iy * xs.len() + ix]`.
    pub z_m: Vec<f64>,
}

impl HeightMap {
    /// Height at node (ix, iy) (m).
    pub fn at(&self, ix: usize, iy: usize) -> f64 {
        self.z_m[iy * self.xs.len() + ix]
    }
}

fn r_squared(ss_res: f64, ss_tot: f64) -> f64 {
    if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        1.0
    }
}

/// Terms of total degree ≤ d: (0,0); (1,0), (0,1); (2,0), (1,1), (0,2); ...
fn terms(d: usize) -> Vec<(usize, usize)> {
    (0..=d)
        .flat_map(|t| (0..=t).rev().map(move |i| (i, t - i)))
        .collect()
}

fn term_count(d: usize) -> usize {
    (d + 1) * (d + 2) / 2
}

fn design(uv: &[[f64; 2]], d: usize) -> DMatrix<f64> {
    let t = terms(d);
    DMatrix::from_fn(uv.len(), t.len(), |r, c| {
        let (i, j) = t[c];
        // [RS eq. 21]: one monomial term of z = f(x, y) per column.
        uv[r][0].powi(i as i32) * uv[r][1].powi(j as i32)
    })
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, m| acc * (n - m) as f64 / (m + 1) as f64)
}

fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![0.5 * (a + b)],
        _ => (0..n)
            .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Exact heights of `f` at the centres of the 8 × 8 cells of `extent`.
    fn exact_grid(extent: &Extent, f: impl Fn(f64, f64) -> f64) -> Vec<GridSample> {
        let dx = (extent.x_max_m - extent.x_min_m) / 8.0;
        let dy = (extent.y_max_m - extent.y_min_m) / 8.0;
        (0..64)
            .map(|k| {
                let (ix, iy) = (k % 8, k / 8);
                let x = extent.x_min_m + (ix as f64 + 0.5) * dx;
                let y = extent.y_min_m + (iy as f64 + 0.5) * dy;
                GridSample {
                    ix,
                    iy,
                    x_m: x,
                    y_m: y,
                    z_m: f(x, y),
                    points: 1,
                }
            })
            .collect()
    }

    fn cloud_of(
        f: impl Fn(f64, f64) -> f64,
        n_side: usize,
        x0: f64,
        x1: f64,
        y0: f64,
        y1: f64,
    ) -> PointCloud {
        let mut pts = Vec::with_capacity(n_side * n_side);
        for i in 0..n_side {
            for j in 0..n_side {
                let x = x0 + (x1 - x0) * i as f64 / (n_side - 1) as f64;
                let y = y0 + (y1 - y0) * j as f64 / (n_side - 1) as f64;
                pts.push([x as f32, y as f32, f(x, y) as f32]);
            }
        }
        PointCloud::new(pts)
    }

    fn coef_xy(fit: &SurfaceFit, a: usize, b: usize) -> f64 {
        fit.coefficients_xy()
            .iter()
            .find(|t| t.x_power == a && t.y_power == b)
            .map_or(0.0, |t| t.coefficient)
    }

    #[test]
    fn a_plane_is_fitted_exactly_with_r2_one() {
        let cloud = cloud_of(|x, y| 2.0 + 0.8 * x - 0.3 * y, 120, 5.0, 30.0, -10.0, 10.0);
        let fit = fit_surface(&cloud, &FitParams::default()).unwrap();
        assert_eq!(fit.degree, 1, "{:?}", fit.candidates);
        assert_eq!(fit.samples.len(), 64);
        assert_relative_eq!(fit.r2, 1.0, epsilon = 1e-9);
        assert_relative_eq!(fit.r2_all_points, 1.0, epsilon = 1e-9);
        assert_relative_eq!(coef_xy(&fit, 0, 0), 2.0, epsilon = 1e-4);
        assert_relative_eq!(coef_xy(&fit, 1, 0), 0.8, epsilon = 1e-6);
        assert_relative_eq!(coef_xy(&fit, 0, 1), -0.3, epsilon = 1e-6);
        assert!(fit.rms_residual_m < 1e-5);
        assert!(fit.residuals_m.iter().all(|e| e.abs() < 1e-5));
    }

    #[test]
    fn a_known_quadratic_is_recovered() {
        let f =
            |x: f64, y: f64| 1.0 - 0.5 * x + 0.25 * y + 0.04 * x * x - 0.03 * x * y + 0.02 * y * y;
        let expected = [
            ((0, 0), 1.0),
            ((1, 0), -0.5),
            ((0, 1), 0.25),
            ((2, 0), 0.04),
            ((1, 1), -0.03),
            ((0, 2), 0.02),
        ];
        // From exact samples on the 8 × 8 grid: to rounding.
        let extent = Extent {
            x_min_m: -10.0,
            x_max_m: 10.0,
            y_min_m: -5.0,
            y_max_m: 15.0,
        };
        let samples = exact_grid(&extent, f);
        let fit = fit_samples(&samples, extent, &FitParams::default()).unwrap();
        assert_eq!(fit.degree, 2, "{:?}", fit.candidates);
        for ((a, b), c) in expected {
            assert_relative_eq!(coef_xy(&fit, a, b), c, epsilon = 1e-12);
        }
        // From a cloud: the local-plane heights are biased by ½ f'' r², here
        // 0.04·E[dx²] + 0.02·E[dy²] ≈ 1e-3 m, which only the constant term sees.
        let cloud = cloud_of(f, 200, -10.0, 10.0, -5.0, 15.0);
        let fit = fit_surface(&cloud, &FitParams::default()).unwrap();
        assert_eq!(fit.degree, 2, "{:?}", fit.candidates);
        for ((a, b), c) in expected {
            let tol = if (a, b) == (0, 0) { 2e-3 } else { 1e-4 };
            assert_relative_eq!(coef_xy(&fit, a, b), c, epsilon = tol);
        }
        assert_relative_eq!(fit.r2, 1.0, epsilon = 1e-8);
        assert_relative_eq!(fit.height(3.0, 4.0), f(3.0, 4.0), epsilon = 2e-3);
    }

    #[test]
    fn a_fixed_degree_is_used_and_exact_samples_need_no_cloud() {
        let f = |x: f64, y: f64| x * x * x - 2.0 * x * y * y + 0.5;
        let extent = Extent {
            x_min_m: -1.0,
            x_max_m: 1.0,
            y_min_m: -1.0,
            y_max_m: 1.0,
        };
        let samples = exact_grid(&extent, f);
        let params = FitParams {
            degree: Some(3),
            ..FitParams::default()
        };
        let fit = fit_samples(&samples, extent, &params).unwrap();
        assert_eq!(fit.degree, 3);
        assert_eq!(fit.candidates.len(), 1);
        assert_relative_eq!(coef_xy(&fit, 3, 0), 1.0, epsilon = 1e-10);
        assert_relative_eq!(coef_xy(&fit, 1, 2), -2.0, epsilon = 1e-10);
        assert_relative_eq!(coef_xy(&fit, 0, 0), 0.5, epsilon = 1e-10);
        // Auto picks 3 as well: 4 and 5 cannot beat an exact fit by 2 %.
        let auto = fit_samples(&samples, extent, &FitParams::default()).unwrap();
        assert_eq!(auto.degree, 3, "{:?}", auto.candidates);
    }

    #[test]
    fn pure_noise_is_refused() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let pts = (0..20_000)
            .map(|_| {
                [
                    rng.gen_range(0.0..10.0f32),
                    rng.gen_range(0.0..10.0f32),
                    rng.gen_range(0.0..1.0f32),
                ]
            })
            .collect();
        let err = fit_surface(&PointCloud::new(pts), &FitParams::default()).unwrap_err();
        match err {
            SurfaceError::PoorFit { r2, threshold, .. } => {
                assert!(r2 < 0.6, "r2 = {r2}");
                assert_relative_eq!(threshold, 0.95);
            }
            e => panic!("expected PoorFit, got {e}"),
        }
    }

    #[test]
    fn the_threshold_can_be_lowered_or_disabled() {
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        // A slope with noise of about 60 % of its variance.
        let pts: Vec<[f32; 3]> = (0..20_000)
            .map(|_| {
                let x: f32 = rng.gen_range(0.0..10.0);
                let y: f32 = rng.gen_range(0.0..10.0);
                [x, y, 0.1 * x + rng.gen_range(-0.5..0.5)]
            })
            .collect();
        let cloud = PointCloud::new(pts);
        assert!(matches!(
            fit_surface(&cloud, &FitParams::default()),
            Err(SurfaceError::PoorFit { .. })
        ));
        let fit = fit_surface(
            &cloud,
            &FitParams {
                r2_threshold: None,
                ..FitParams::default()
            },
        )
        .unwrap();
        assert!(fit.r2 < 0.95 && fit.r2 > 0.5, "{}", fit.r2);
        assert!(
            fit.r2_all_points < fit.r2,
            "the median samples are less noisy than the points"
        );
    }

    #[test]
    fn degenerate_and_bad_parameters() {
        let cloud = cloud_of(|x, _| x, 50, 0.0, 1.0, 0.0, 1.0);
        let err = fit_surface(
            &cloud,
            &FitParams {
                max_degree: 0,
                ..FitParams::default()
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("FitParams.max_degree"), "{err}");
        let err = fit_surface(
            &cloud,
            &FitParams {
                r2_threshold: Some(1.0),
                ..FitParams::default()
            },
        )
        .unwrap_err();
        assert!(err.to_string().contains("FitParams.r2_threshold"), "{err}");
        // Samples on a single line of y: no plane through them.
        let samples: Vec<GridSample> = (0..8)
            .map(|ix| GridSample {
                ix,
                iy: 0,
                x_m: ix as f64,
                y_m: 0.0,
                z_m: ix as f64,
                points: 1,
            })
            .collect();
        let extent = Extent {
            x_min_m: 0.0,
            x_max_m: 8.0,
            y_min_m: -1.0,
            y_max_m: 1.0,
        };
        let err = fit_samples(&samples, extent, &FitParams::default()).unwrap_err();
        assert!(
            matches!(
                err,
                SurfaceError::DegenerateSamples {
                    rank: 2,
                    terms: 3,
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn height_map_and_binomial_expansion_agree() {
        let f = |x: f64, y: f64| 3.0 + 0.2 * x * x - 0.1 * y + 0.01 * x * y * y;
        let cloud = cloud_of(f, 150, 2.0, 12.0, -3.0, 7.0);
        let fit = fit_surface(
            &cloud,
            &FitParams {
                degree: Some(3),
                ..FitParams::default()
            },
        )
        .unwrap();
        let map = fit.grid(5, 4);
        assert_eq!(map.z_m.len(), 20);
        let xy = fit.coefficients_xy();
        for (ix, &x) in map.xs.iter().enumerate() {
            for (iy, &y) in map.ys.iter().enumerate() {
                let plain: f64 = xy
                    .iter()
                    .map(|t| t.coefficient * x.powi(t.x_power as i32) * y.powi(t.y_power as i32))
                    .sum();
                assert_relative_eq!(map.at(ix, iy), plain, epsilon = 1e-9);
                assert_relative_eq!(map.at(ix, iy), f(x, y), epsilon = 5e-3);
            }
        }
    }
}
