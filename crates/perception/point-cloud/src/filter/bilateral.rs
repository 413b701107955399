//! Bilateral smoothing along normals ([RS eq. 19]–[RS eq. 20]): each
//! point moves along its unit normal n_P by
//!
//! ```text
//! P' = P + δ_P · n_P                                                    (19)
//! δ_P = Σ_q w_d(‖q − P‖) w_n(|⟨n_P, q − P⟩|) ⟨n_P, q − P⟩
//!       / Σ_q w_d(‖q − P‖) w_n(|⟨n_P, q − P⟩|)                           (20)
//! ```
//!
//! over the points q of the neighbourhood N_r(P) (the points within
//! `radius_m`, inclusive, P itself excluded: it adds weight 1 to the
//! denominator and nothing to the numerator, which would only damp δ), with
//! the Gaussian weights the paper names, w_d(x) = exp(−x² / 2σ_d²) and
//! w_n(y) = exp(−y² / 2σ_n²). n_P is the PCA normal of N_r(P), P included
//! (see `normals.rs`); its sign does not matter, since δ_P·n_P is the same
//! for −n_P. A point without a normal (fewer than 3 points in N_r(P), or
//! collinear ones) or without neighbours stays where it is. Each iteration
//! moves every point from the previous iteration's positions (a Jacobi
//! update, so the result does not depend on the order of the points), with
//! fresh neighbourhoods and normals; sums are in f64, positions stored as f32.
//!
//! This is the bilateral filter for point sets of Fleishman, Drori and
//! Cohen-Or (2003), as the paper states it. Neither PCL's filters
//! (`pcl::BilateralFilter` smooths intensities of organized clouds) nor
//! Open3D have it, so there is no peer to agree with: the tests check
//! closed forms instead (a plane stays put, a single raised point returns to
//! its plane, noise on a plane shrinks).

use super::common::{bad, empty_input, f32_at_most, is_finite};
use super::exp::exp_in_place;
use super::normals::{add_lanes, pca_normal, Columns, LANES};
use crate::search::columns::ColumnGrid;
use crate::search::kdtree::KdTree;
use crate::simd::Isa;
use crate::{Point, PointCloud, Result};
use autoshovel_core::config::short;
use serde::{Deserialize, Serialize};

const FILTER: &str = "bilateral normal smoothing";

/// A point's neighbourhood in f64 columns, and its exponents (then
/// weights) and offsets along its normal, one a neighbour.
#[derive(Default)]
struct Terms {
    near: Columns,
    weight: Vec<f64>,
    offset: Vec<f64>,
}

/// Parameters of [`bilateral_normal_smoothing`] ([RS eq. 19]–[RS eq. 20]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BilateralParams {
    /// The neighbourhood radius r of N_r(P) (m), inclusive.
    pub radius_m: f64,
    /// σ_d of the distance weight w_d (m).
    pub sigma_d_m: f64,
    /// σ_n of the normal-offset weight w_n (m).
    pub sigma_n_m: f64,
    /// Number of smoothing passes.
    pub iterations: usize,
}

impl Default for BilateralParams {
    /// The paper gives no values (documented choice, for a pile down-sampled
    /// to 5 cm voxels): r = 0.15 m (a few voxels), σ_d = r / 2, σ_n = 0.02 m
    /// (about the range noise, so that edges taller than that survive), one pass.
    fn default() -> Self {
        Self {
            radius_m: 0.15,
            sigma_d_m: 0.075,
            sigma_n_m: 0.02,
            iterations: 1,
        }
    }
}

impl BilateralParams {
    fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("radius_m", self.radius_m),
            ("sigma_d_m", self.sigma_d_m),
            ("sigma_n_m", self.sigma_n_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(
                    FILTER,
                    format!("{name} must be positive and finite, got {}", short(v)),
                ));
            }
        }
        if self.iterations == 0 {
            return Err(bad(FILTER, "iterations must be at least 1, got 0".into()));
        }
        Ok(())
    }
}

/// The cloud smoothed by [RS eq. 19]–[RS eq. 20], point for point in input order
/// (non-finite points are dropped, as by every filter here).
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// // A flat 11 × 11 grid of 1 cm spacing with its centre raised by 5 mm:
/// // with its 4 neighbours at 1 cm (r = 1.2 cm) the centre returns to the
/// // plane (closed form of [RS eq. 20]: every offset is −5 mm, so δ = −5 mm).
/// let mut points: Vec<[f32; 3]> =
///     (0..121).map(|i| [(i % 11) as f32 * 0.01, (i / 11) as f32 * 0.01, 0.0]).collect();
/// points[60][2] = 0.005;
/// let params = filter::BilateralParams { radius_m: 0.012, sigma_d_m: 0.01, sigma_n_m: 0.01, iterations: 1 };
/// let smoothed = filter::bilateral_normal_smoothing(&PointCloud::new(points), &params).unwrap();
/// assert!(smoothed.points[60][2].abs() < 1e-6);
/// ```
pub fn bilateral_normal_smoothing(cloud: &[Point], params: &BilateralParams) -> Result<PointCloud> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let mut points: Vec<Point> = cloud.iter().copied().filter(is_finite).collect();
    if points.is_empty() {
        return Err(super::common::emptied(
            FILTER,
            cloud.len(),
            "every point has a non-finite coordinate",
        ));
    }
    let r2 = f32_at_most(params.radius_m * params.radius_m);
    let (inv_2sd2, inv_2sn2) = (
        1.0 / (2.0 * params.sigma_d_m * params.sigma_d_m),
        1.0 / (2.0 * params.sigma_n_m * params.sigma_n_m),
    );
    let radius = f64::from(r2).sqrt();
    let isa = Isa::best();
    for _ in 0..params.iterations {
        let current = &points;
        // [RS eq. 19]–[RS eq. 20] for point `i` from its neighbours within
        // the radius, in input order, so that the sums' rounding does not
        // depend on the search (the same points give the same result in any
        // cloud that holds their neighbourhood: a tile with its margin).
        let smooth = |terms: &mut Terms, i: usize, found: &[u32]| -> Point {
            let p = &current[i];
            let Terms {
                near,
                weight,
                offset,
            } = terms;
            near.gather(p, current, found);
            let Some(n) = pca_normal(near) else {
                return *p;
            };
            let pf = p.map(f64::from);
            // Every neighbour's terms at once (P's own are dropped below):
            // no term depends on another, so the loop runs by vector.
            weight.resize(near.x.len(), 0.0);
            offset.resize(near.x.len(), 0.0);
            for ((((w, h), &x), &y), &z) in weight
                .iter_mut()
                .zip(offset.iter_mut())
                .zip(&near.x)
                .zip(&near.y)
                .zip(&near.z)
            {
                let dist2 = x * x + y * y + z * z;
                *h = n[0] * x + n[1] * y + n[2] * z;
                // [RS eq. 19]: w = w_d(‖p − p_j‖) · w_n(⟨n, p_j − p⟩), two
                // Gaussians taken as one exponential of their exponents' sum
                // (all of a point's at once, `exp.rs`).
                *w = -(dist2 * inv_2sd2 + *h * *h * inv_2sn2);
            }
            // P's own terms out (its neighbours come ascending, in input order).
            if let Ok(own) = found.binary_search(&(i as u32)) {
                weight.remove(own);
                offset.remove(own);
            }
            exp_in_place(isa, weight);
            // Σ w·h and Σ w, LANES sums of each side by side.
            let (mut num, mut den) = ([0.0_f64; LANES], [0.0_f64; LANES]);
            let whole = weight.len() / LANES * LANES;
            for (w, h) in weight[..whole]
                .chunks_exact(LANES)
                .zip(offset.chunks_exact(LANES))
            {
                for l in 0..LANES {
                    num[l] += w[l] * h[l];
                    den[l] += w[l];
                }
            }
            let (mut num, mut den) = (add_lanes(num), add_lanes(den));
            for (&w, &h) in weight[whole..].iter().zip(&offset[whole..]) {
                num += w * h;
                den += w;
            }
            if den > 0.0 {
                // [RS eq. 20]: δ = Σ w·h / Σ w, the point moved along its normal.
                let delta = num / den;
                [0, 1, 2].map(|a| (pf[a] + delta * n[a]) as f32)
            } else {
                *p
            }
        };
        // On a grid of columns as wide as the radius when the cloud suits
        // one (`search::columns`), else on the k-d tree: the same neighbours.
        points = match ColumnGrid::for_radius(current, radius) {
            Some(grid) => grid.map_within(r2, Terms::default, smooth),
            None => {
                let tree = KdTree::new(current);
                tree.map_points(
                    || (Vec::new(), Terms::default()),
                    |(found, terms), pos, p| {
                        tree.within(p, r2, found);
                        for q in found.iter_mut() {
                            *q = tree.id(*q as usize) as u32;
                        }
                        found.sort_unstable();
                        smooth(terms, tree.id(pos), found)
                    },
                )
            }
        };
    }
    Ok(PointCloud::new(points))
}
