//! Statistical outlier removal ([RS eq. 14]–[RS eq. 16]): each point's
//! mean distance d̄_i to its k nearest neighbours; their global mean d̄ and
//! sample standard deviation δ ([RS eq. 14], with n − 1); d̄_i ~ N(d̄, δ²) ([RS eq. 15]);
//! a point is noise when d̄_i − d̄ > α·δ ([RS eq. 16], one-sided as in PCL).
//!
//! The paper writes eq. 16 two-sided, |d̄_i − d̄| > α·δ: it would also drop
//! points whose neighbours are unusually *close* (dense clusters, duplicated
//! returns, the near field of a LiDAR). PCL, Open3D and CloudCompare all cut
//! one side only, and so does [`OutlierSides::Above`], the default; the
//! paper's rule is [`OutlierSides::Both`]. With α ≥ 0 the two differ only in
//! the points with d̄_i < d̄ − α·δ.
//!
//! Semantics of PCL 1.13.0's `pcl::StatisticalOutlierRemoval<PointT>`, followed
//! to the bit (`filters/include/pcl/filters/impl/statistical_outlier_removal.hpp`,
//! `applyFilterIndices`; the floating-point operations below were also read
//! off the disassembly of Debian's `libpcl_filters.so.1.13.0`):
//!
//! ```text
//! searcher_->nearestKSearch ((*indices_)[iii], mean_k_ + 1, nn_indices, nn_dists)
//! double dist_sum = 0.0;
//! for (int k = 1; k < mean_k_ + 1; ++k)  // k = 0 is the query point
//!   dist_sum += sqrt (nn_dists[k]);      // sqrtsd of the f32 widened to f64
//! distances[iii] = static_cast<float> (dist_sum / mean_k_);
//! ...
//! for (const float &distance : distances) { sum += distance; sq_sum += distance * distance; }
//!                                          // f64 sums; distance * distance in f32
//! double mean = sum / valid_distances;
//! double variance = (sq_sum - sum * sum / valid_distances) / (valid_distances - 1);
//! double stddev = sqrt (variance);
//! double distance_threshold = mean + std_mul_ * stddev;
//! if (distances[iii] > distance_threshold) → removed   // kept: d̄_i <= threshold
//! ```
//!
//! The k neighbours exclude the first of the k + 1 nearest (the point itself,
//! or an exact duplicate: both at distance 0); they are summed nearest first.
//! The global sums run sequentially in input order (never in parallel, whose
//! rounding would depend on the split). A negative variance from rounding
//! gives a NaN threshold in PCL, which then keeps every point: so do we.
//!
//! The PCL 1.13 tool `pcl_outlier_removal -method statistical -mean_k K
//! -std_dev_mul S` keeps exactly what `StatisticalOutlierParams { mean_k: K,
//! std_mul: S }` keeps (tests/filter_pcl_agreement.rs). Open3D 0.20's
//! `remove_statistical_outlier(nb_neighbors, std_ratio)` differs in
//! details: its nb_neighbors nearest include the point itself (so
//! `nb_neighbors = k + 1` averages our k distances and a zero, which scales
//! every mean by k/(k + 1) and the threshold with it), it computes in f64,
//! and it keeps `0 < d̄_i < threshold` (strict); like PCL it uses the
//! sample standard deviation.

use super::common::{bad, emptied, empty_input, gather, on_finite_points};
use crate::search::columns::ColumnGrid;
use crate::search::kdtree::KdTree;
use crate::search::octree::Octree;
use crate::simd::{Isa, Path};
use crate::{Point, PointCloud, Result};
use autoshovel_core::config::short;
use serde::{Deserialize, Serialize};

const FILTER: &str = "statistical outlier removal";

/// Which deviations of [RS eq. 16] make a point noise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutlierSides {
    /// d̄_i − d̄ > α·δ: only points far from their neighbours (PCL's
    /// `StatisticalOutlierRemoval`, Open3D, CloudCompare). The default.
    #[default]
    Above,
    /// |d̄_i − d̄| > α·δ: also points unusually close to their neighbours,
    /// as [RS eq. 16] is printed.
    Both,
}

/// Parameters of [`statistical_outlier_removal`] ([RS eq. 14]–[RS eq. 16]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StatisticalOutlierParams {
    /// The number k of neighbours (not counting the point) whose mean
    /// distance d̄_i is taken (PCL's `mean_k_`, `-mean_k`).
    pub mean_k: usize,
    /// The threshold factor α of [RS eq. 16] (PCL's `std_mul_`, `-std_dev_mul`).
    pub std_mul: f64,
    /// One-sided as PCL (the default) or two-sided as [RS eq. 16] prints it.
    pub sides: OutlierSides,
}

impl Default for StatisticalOutlierParams {
    /// The paper gives no values: k = 50, α = 1 (PCL's tutorial values,
    /// documented choice).
    fn default() -> Self {
        Self {
            mean_k: 50,
            std_mul: 1.0,
            sides: OutlierSides::Above,
        }
    }
}

impl StatisticalOutlierParams {
    fn validate(&self) -> Result<()> {
        if self.mean_k == 0 || self.mean_k >= u32::MAX as usize {
            return Err(bad(
                FILTER,
                format!("mean_k must be at least 1, got {}", self.mean_k),
            ));
        }
        if !self.std_mul.is_finite() {
            return Err(bad(
                FILTER,
                format!("std_mul must be finite, got {}", short(self.std_mul)),
            ));
        }
        if self.sides == OutlierSides::Both && self.std_mul < 0.0 {
            return Err(bad(
                FILTER,
                format!(
                    "std_mul must be at least 0 with sides = both (|d̄_i − d̄| > α·δ), got {}",
                    short(self.std_mul)
                ),
            ));
        }
        Ok(())
    }
}

/// Indices of the points kept by statistical outlier removal, in input order.
pub fn statistical_outlier_removal_indices(
    cloud: &[Point],
    params: &StatisticalOutlierParams,
) -> Result<Vec<usize>> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let kept = on_finite_points(cloud, |points| kept_indices(points, params))?;
    if kept.is_empty() {
        return Err(emptied(FILTER, cloud.len(), "raise std_mul"));
    }
    Ok(kept)
}

/// The points kept by statistical outlier removal ([RS eq. 14]–[RS eq. 16]), in input order.
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// // A 10 × 10 grid of 1 cm spacing and one point 1 m above it.
/// let mut points: Vec<[f32; 3]> =
///     (0..100).map(|i| [(i % 10) as f32 * 0.01, (i / 10) as f32 * 0.01, 0.0]).collect();
/// points.push([0.05, 0.05, 1.0]);
/// let cloud = PointCloud::new(points);
/// let params = filter::StatisticalOutlierParams { mean_k: 8, std_mul: 1.0, ..Default::default() };
/// let kept = filter::statistical_outlier_removal(&cloud, &params).unwrap();
/// assert!(kept.points.iter().all(|p| p[2] == 0.0));
/// ```
pub fn statistical_outlier_removal(
    cloud: &[Point],
    params: &StatisticalOutlierParams,
) -> Result<PointCloud> {
    let kept = statistical_outlier_removal_indices(cloud, params)?;
    Ok(gather(cloud, &kept))
}

/// The mean distance d̄_i of every point to its k nearest neighbours, as PCL
/// computes it (f64 sum of f64 square roots of f32 squared distances,
/// nearest first, divided by k, stored as f32; see `mean_of`).
pub(crate) fn mean_neighbour_distances(points: &[Point], mean_k: usize) -> Vec<f32> {
    k_nearest_distances(points, mean_k + 1, |nearest| mean_of(nearest, mean_k))
}

/// `f` of every point's k nearest squared distances (the point itself
/// counted; in any order, the k-th last), in input order: on the octree
/// (`search::octree`) when the density varies widely ([`uneven`], probed on
/// a sample), else on the grid of columns when the cloud suits one
/// (`search::columns`), else on the k-d tree; the same bits every way.
fn k_nearest_distances<T, F>(points: &[Point], k: usize, f: F) -> Vec<T>
where
    T: Send + Sync + Clone + Default,
    F: Fn(&[f32]) -> T + Sync + Send,
{
    // The octree's finest cell (0: as fine as codes go), or none.
    let octree = match Search::chosen() {
        Search::ColumnGrid => None,
        Search::Octree => Some(0.0),
        Search::Chosen => {
            let kth = probe_k_nearest(points, k);
            // A quarter of the least k-th distance probed: at the densest
            // place probed, a cell holds a point or so.
            uneven(&kth).then(|| kth[0] / FINEST)
        }
    };
    if let Some(finest) = octree {
        if let Some(tree) = Octree::with_finest(points, finest) {
            return tree.map_k_nearest_distances(k, f);
        }
    }
    match ColumnGrid::for_k_nearest(points, k) {
        Some(grid) => grid.map_k_nearest_distances(k, f),
        None => KdTree::new(points).map_k_nearest_distances(k, f),
    }
}

/// The octree's cells are no finer than the least probed k-th distance
/// over this (`Octree::with_finest`).
const FINEST: f64 = 4.0;

/// Points whose k-th distance [`uneven`] reads.
const PROBES: usize = 256;

/// A cloud is searched on the octree when the upper quartile of its
/// probed k-th distances ([`probe_k_nearest`]) is more than this times
/// the lower quartile.
///
/// Measured (BENCHMARKS.md, 2026-12-06; the spread on the sample, then
/// grid against octree): PCL's five RGB-D scans side by side (`kinect5`)
/// 4.3, the octree about 0.6–0.7 of the grid's time; each of those scans
/// alone 1.6–2.3, the bench pile 1.3, the rosette scan 1.6 and a 100 k
/// frame 1.8, where the grid is as fast or up to twice as fast (the
/// octree's gathers read a box round a group of points, which costs most
/// where the scan is a layer as thick as the k-th distance: the pile, the
/// rosette). Probing costs the bench pile 2–5 % of the filter's time.
const UNEVEN: f64 = 2.5;

/// Points of the sample that [`probe_k_nearest`] probes a neighbour a
/// point of the cloud would have.
const SAMPLE_K: usize = 8;

/// The k-th distances of [`PROBES`] points, ascending, estimated on a
/// sample of every m-th point (m = k / [`SAMPLE_K`], at least 1) as their
/// (k / m)-th distances among the sample: the same distance where the
/// density is even over m points, found on an octree of a sixth of the
/// cloud (k = 51). Probing on the whole cloud's octree cost the bench
/// pile's filter about 10 %; on the sample, 2–5 %.
fn probe_k_nearest(points: &[Point], k: usize) -> Vec<f64> {
    let m = (k / SAMPLE_K).max(1);
    let sample: Vec<Point> = points.iter().step_by(m).copied().collect();
    let kth = (k / m).clamp(1, sample.len());
    Octree::new(&sample).map_or_else(Vec::new, |t| t.probe_k_nearest(kth, PROBES))
}

/// Whether the k-th distances `kth` (ascending) spread past [`UNEVEN`].
fn uneven(kth: &[f64]) -> bool {
    if kth.len() < 4 {
        return false;
    }
    let quartile = |f: f64| kth[((kth.len() - 1) as f64 * f).round() as usize];
    quartile(0.75) > UNEVEN * quartile(0.25)
}

/// Which search the k nearest take ([`k_nearest_distances`]): chosen by
/// the cloud, or held to one by the environment variable
/// `AUTOSHOVEL_SEARCH` (`grid`, `octree`), as benchmarks compare them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Search {
    Chosen,
    ColumnGrid,
    Octree,
}

impl Search {
    fn chosen() -> Self {
        static CHOSEN: std::sync::OnceLock<Search> = std::sync::OnceLock::new();
        *CHOSEN.get_or_init(|| match std::env::var("AUTOSHOVEL_SEARCH").as_deref() {
            Ok("grid") => Search::ColumnGrid,
            Ok("octree") => Search::Octree,
            _ => Search::Chosen,
        })
    }
}

/// The mean distance d̄_i of every point to its k nearest neighbours (as
/// [`statistical_outlier_removal`] computes it) and the squared distance
/// to the k-th of them: how far the point's neighbourhood reaches, so that a
/// caller holding part of a larger cloud (a tile with its margin) can tell
/// whether the neighbours it did not load could have mattered.
pub fn mean_distances_and_reach(points: &[Point], mean_k: usize) -> Result<Vec<(f32, f32)>> {
    enough_points(points.len(), mean_k)?;
    Ok(k_nearest_distances(points, mean_k + 1, |nearest| {
        (mean_of(nearest, mean_k), nearest[nearest.len() - 1])
    }))
}

/// `mean_k` nearest neighbours need `mean_k + 1` points.
fn enough_points(n: usize, mean_k: usize) -> Result<()> {
    if mean_k == 0 || mean_k >= n {
        return Err(bad(
            FILTER,
            format!(
                "mean_k = {mean_k} needs at least {} finite points, the cloud has {n}",
                mean_k + 1,
            ),
        ));
    }
    Ok(())
}

/// [`mean_distances_and_reach`] of the points `queries` among `points`
/// (each query one of `points`: the first of its k + 1 nearest is itself).
pub fn mean_distances_and_reach_at(
    points: &[Point],
    queries: &[Point],
    mean_k: usize,
) -> Result<Vec<(f32, f32)>> {
    use rayon::prelude::*;
    enough_points(points.len(), mean_k)?;
    let tree = KdTree::new(points);
    Ok(queries
        .par_iter()
        .map_init(
            || crate::search::kdtree::Nearest::new(mean_k + 1),
            |knn, q| {
                tree.nearest(q, knn);
                let nearest = knn.distances();
                (mean_of(nearest, mean_k), nearest[nearest.len() - 1])
            },
        )
        .collect())
}

/// d̄_i from the k + 1 nearest squared distances (the first of them, in
/// PCL's order, is the point itself at 0, which adds nothing), as PCL
/// computes it: the f64 sum of their f64 roots nearest first, over k, as f32.
///
/// The k + 1 come in any order (the k-th last): sorting them for every
/// point would cost more than the search. They are summed in lanes (on
/// AVX-512 with roots of a known error, [`ROOT_ERROR`]), and the sum is
/// PCL's to the bit whenever it is clear of an f32 rounding boundary by
/// more than the two sums can differ: any order of summing k + 1 positive
/// terms lies within (k + 1)·2⁻⁵³ of their exact sum, so PCL's and ours
/// within twice that (and the roots' error) of each other. In the rare
/// other case (about 2 points in 10⁶) the distances are sorted and summed
/// in PCL's order.
fn mean_of(nearest: &[f32], mean_k: usize) -> f32 {
    mean_of_on(Isa::best(), nearest, mean_k)
}

fn mean_of_on(isa: Isa, nearest: &[f32], mean_k: usize) -> f32 {
    let sum = root_sum_on(isa, nearest);
    let k = mean_k as f64;
    let mean = sum / k;
    // Both sums within n·2⁻⁵³·sum of the exact one (ours also within the
    // roots' relative error); a relative 4n·2⁻⁵³ and four times that
    // error (and two f64 roundings of the quotient) bound where PCL's
    // quotient can lie.
    let relative = 4.0 * (nearest.len() as f64 + 2.0) * f64::EPSILON + 4.0 * ROOT_ERROR;
    let gap = mean * relative;
    let (low, high) = ((mean - gap) as f32, (mean + gap) as f32);
    if low == high {
        return low;
    }
    let mut sorted = nearest.to_vec();
    sorted.sort_unstable_by(f32::total_cmp);
    let sum = sorted[1..]
        .iter()
        .fold(0.0_f64, |s, &d| s + f64::from(d).sqrt());
    (sum / k) as f32
}

/// The relative error of a root on AVX-512 ([`avx512::root_sum`]) is
/// below this (measured within one ulp, 2.2e-16, on every f32 mantissa:
/// a margin of 64).
const ROOT_ERROR: f64 = 1.0 / (1u64 << 46) as f64;

/// Σ √d over `nearest` in f64 (roots within [`ROOT_ERROR`] of the exact
/// ones, sums in any order). The portable and AVX2 paths sum the f64
/// roots in four lanes (lane j sums elements j, j + 4, …), then
/// (l₀ + l₁) + (l₂ + l₃) + the rest, the same bits on both (each root and
/// sum is rounded as IEEE 754 says and the order is fixed; AVX2 takes four
/// roots an instruction, SSE2, the baseline, two). AVX-512 computes the
/// roots by Newton's method instead ([`avx512::root_sum`]): `vsqrtpd` is
/// slow (12 % of the statistical filter on `kinect5`), and the roots by
/// multiplies alone took 2 % off the filter (172 to 168 ms and 185 to 181
/// ms, medians of eight alternated rounds; 55 against 35–43 ns for 51
/// roots alone).
fn root_sum_on(isa: Isa, nearest: &[f32]) -> f64 {
    #[inline(always)]
    fn body(nearest: &[f32]) -> f64 {
        let mut lanes = [0.0f64; 4];
        let mut chunks = nearest.chunks_exact(4);
        for c in &mut chunks {
            for (lane, &d) in lanes.iter_mut().zip(c) {
                *lane += f64::from(d).sqrt();
            }
        }
        let rest: f64 = chunks
            .remainder()
            .iter()
            .map(|&d| f64::from(d).sqrt())
            .sum();
        (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest
    }
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn wide(nearest: &[f32]) -> f64 {
        body(nearest)
    }
    match isa.path() {
        Path::Portable => body(nearest),
        // SAFETY: `_t` proves AVX2, `wide`'s one requirement.
        #[cfg(target_arch = "x86_64")]
        Path::Avx2(_t) => unsafe { wide(nearest) },
        // SAFETY: `t` proves AVX-512F, the kernel's one requirement.
        #[cfg(target_arch = "x86_64")]
        Path::Avx512(t) => unsafe { avx512::root_sum(t, nearest) },
    }
}

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use std::arch::x86_64::*;

    /// The roots of eight f64 `x ≥ 0` (+∞ and NaN as `sqrt`), each within
    /// one ulp of the exact root (measured on every f32 mantissa): a 14-bit
    /// estimate of 1/√x (`vrsqrt14pd`, documented below 2⁻¹⁴), one Newton
    /// step for 1/√x (below 2⁻²⁷), then √x ≈ x/√x and one Newton step for
    /// √x on the fused residual x − y² (below 1.5·2⁻⁵⁴ plus the roundings).
    #[inline]
    #[target_feature(enable = "avx512f")]
    fn roots(x: __m512d) -> __m512d {
        let half = _mm512_set1_pd(0.5);
        let r0 = _mm512_rsqrt14_pd(x);
        // r1 = r0·(1.5 − ½x·r0²)
        let hx = _mm512_mul_pd(half, x);
        let t = _mm512_fnmadd_pd(_mm512_mul_pd(hx, r0), r0, _mm512_set1_pd(1.5));
        let r1 = _mm512_mul_pd(r0, t);
        // y = x·r1, then y + (x − y²)·r1/2
        let y = _mm512_mul_pd(x, r1);
        let e = _mm512_fnmadd_pd(y, y, x);
        let y = _mm512_fmadd_pd(e, _mm512_mul_pd(half, r1), y);
        // 0 and +∞ (where 1/√x is +∞ or 0) and NaN are their own roots.
        let exact = _mm512_cmp_pd_mask(x, _mm512_setzero_pd(), _CMP_EQ_OQ)
            | _mm512_cmp_pd_mask(x, _mm512_set1_pd(f64::INFINITY), _CMP_EQ_OQ)
            | _mm512_cmp_pd_mask(x, x, _CMP_UNORD_Q);
        _mm512_mask_blend_pd(exact, y, x)
    }

    /// Σ √d over `nearest` (each d ≥ +0 or NaN), the roots by [`roots`],
    /// summed in eight lanes, then across them.
    ///
    /// # Safety
    /// AVX-512F.
    #[target_feature(enable = "avx512f")]
    pub(super) unsafe fn root_sum(_: crate::simd::Avx512, nearest: &[f32]) -> f64 {
        let n = nearest.len();
        let mut sum = _mm512_setzero_pd();
        let mut i = 0;
        while i < n {
            let step: __mmask16 = if n - i >= 16 {
                u16::MAX
            } else {
                (1u16 << (n - i)) - 1
            };
            // SAFETY: a load masked to the slice (the other lanes read 0,
            // whose roots are 0).
            let d = unsafe { _mm512_maskz_loadu_ps(step, nearest.as_ptr().add(i)) };
            let low = _mm512_cvtps_pd(_mm512_castps512_ps256(d));
            let high = _mm512_cvtps_pd(_mm256_castsi256_ps(_mm512_extracti64x4_epi64::<1>(
                _mm512_castps_si512(d),
            )));
            sum = _mm512_add_pd(sum, _mm512_add_pd(roots(low), roots(high)));
            i += 16;
        }
        _mm512_reduce_add_pd(sum)
    }
}

/// The global sums of [RS eq. 14] in PCL's arithmetic (f64 sums, the square
/// in f32), to be added in input order: the order fixes the rounding, so a
/// caller that computes d̄_i by parts adds them back in the cloud's order.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct DistanceSums {
    sum: f64,
    sq_sum: f64,
    n: u64,
}

impl DistanceSums {
    /// Adds the next point's d̄_i.
    #[inline]
    pub fn add(&mut self, d: f32) {
        self.sum += f64::from(d);
        self.sq_sum += f64::from(d * d);
        self.n += 1;
    }

    /// How many d̄_i were added.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// The cut of [RS eq. 15]–[RS eq. 16] these sums give.
    pub fn cut(&self, params: &StatisticalOutlierParams) -> OutlierCut {
        let n = self.n as f64;
        // [RS eq. 14]: the mean d̄ and standard deviation δ (n − 1) of the mean distances;
        let mean = self.sum / n;
        let variance = (self.sq_sum - self.sum * self.sum / n) / (n - 1.0);
        // [RS eq. 15]: d̄_i ~ N(d̄, δ²), so the cut sits at d̄ + α·δ.
        let spread = params.std_mul * variance.sqrt();
        let threshold = mean + spread;
        // [RS eq. 16]: removed when d̄_i > threshold (PCL), or also when
        // d̄_i < d̄ − α·δ (two-sided); a NaN threshold removes nothing.
        let low = match params.sides {
            OutlierSides::Above => f64::NEG_INFINITY,
            OutlierSides::Both => mean - spread,
        };
        OutlierCut {
            low,
            high: threshold,
        }
    }
}

/// Which d̄_i are kept ([RS eq. 16]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutlierCut {
    /// Kept at or above (−∞ one-sided).
    pub low: f64,
    /// Kept at or below; NaN keeps every point, as in PCL.
    pub high: f64,
}

impl OutlierCut {
    /// Whether a point with mean distance `d` is kept.
    #[inline]
    pub fn keeps(&self, d: f32) -> bool {
        let d = f64::from(d);
        self.high.is_nan() || (d <= self.high && d >= self.low)
    }
}

/// The kept indices of `points` (all finite, not empty).
fn kept_indices(points: &[Point], params: &StatisticalOutlierParams) -> Result<Vec<usize>> {
    enough_points(points.len(), params.mean_k)?;
    Ok(cut_kept(
        &mean_neighbour_distances(points, params.mean_k),
        params,
    ))
}

/// [`statistical_outlier_removal_indices`] of the points filed on `grid`,
/// which are those at `filed` (ascending, not empty) of some cloud: indices
/// into `filed`.
pub(crate) fn statistical_kept_on(
    grid: &ColumnGrid,
    filed: &[usize],
    params: &StatisticalOutlierParams,
) -> Result<Vec<usize>> {
    params.validate()?;
    let n = filed.len();
    enough_points(n, params.mean_k)?;
    let k = params.mean_k;
    let all = grid.map_k_nearest_distances(k + 1, |nearest| mean_of(nearest, k));
    let distances: Vec<f32> = filed.iter().map(|&i| all[i]).collect();
    let kept = cut_kept(&distances, params);
    if kept.is_empty() {
        return Err(emptied(FILTER, n, "raise std_mul"));
    }
    Ok(kept)
}

/// The points whose d̄_i the cut of [RS eq. 15]–[RS eq. 16] keeps, the
/// global sums of [RS eq. 14] added in input order.
fn cut_kept(distances: &[f32], params: &StatisticalOutlierParams) -> Vec<usize> {
    let mut sums = DistanceSums::default();
    for &d in distances {
        sums.add(d);
    }
    let cut = sums.cut(params);
    distances
        .iter()
        .enumerate()
        .filter(|(_, &d)| cut.keeps(d))
        .map(|(i, _)| i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_probe_tells_an_uneven_cloud_from_an_even_one() {
        let mut u = crate::testing::uniform(4);
        // A plane of 200 × 200 points a centimetre apart (jittered).
        let plane = |at: f32, step: f32, u: &mut dyn FnMut() -> f32| -> Vec<Point> {
            (0..40_000)
                .map(|i| {
                    let (x, y) = ((i % 200) as f32 + u(), (i / 200) as f32 + u());
                    [at + x * step, y * step, 0.001 * u()]
                })
                .collect()
        };
        let even = plane(0.0, 0.01, &mut u);
        // The same beside one ten times sparser: the k-th distances of
        // half the points ten times the other half's.
        let mut uneven_cloud = even.clone();
        uneven_cloud.extend(plane(5.0, 0.1, &mut u));
        let k = 51;
        for (points, want) in [(&even, false), (&uneven_cloud, true)] {
            let kth = probe_k_nearest(points, k);
            assert_eq!(kth.len(), PROBES);
            assert_eq!(uneven(&kth), want, "{} points", points.len());
        }
        // The probe's median is near the true median k-th distance of the
        // even plane (√(51/π) ≈ 4 spacings on a plane).
        let kth = probe_k_nearest(&even, k);
        let median = kth[kth.len() / 2];
        assert!((0.03..0.05).contains(&median), "median {median}");
    }

    #[test]
    fn the_root_sum_is_the_same_on_every_path() {
        // Four lanes, then (l0 + l1) + (l2 + l3) + the rest, written out.
        let mut u = crate::testing::uniform(3);
        for n in 0..80 {
            let d: Vec<f32> = (0..n)
                .map(|_| u().abs() * 10f32.powi(n as i32 % 7 - 3))
                .collect();
            let mut lanes = [0.0f64; 4];
            for (i, &x) in d.iter().enumerate().take(n / 4 * 4) {
                lanes[i % 4] += f64::from(x).sqrt();
            }
            let rest = d[n / 4 * 4..]
                .iter()
                .fold(0.0, |s, &x| s + f64::from(x).sqrt());
            let expected = (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + rest;
            for isa in Isa::available() {
                let sum = root_sum_on(isa, &d);
                #[cfg(target_arch = "x86_64")]
                if isa.avx512().is_some() {
                    // Newton's roots and eight lanes: within the bound.
                    let bound = (ROOT_ERROR + 2.0 * n as f64 * f64::EPSILON) * expected;
                    assert!((sum - expected).abs() <= bound, "{n}: {sum} {expected}");
                    continue;
                }
                assert_eq!(sum.to_bits(), expected.to_bits(), "{isa:?}, {n}");
            }
        }
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn newtons_roots_are_within_their_bound_for_every_mantissa() {
        let Some(t) = Isa::best().avx512() else {
            return;
        };
        // SAFETY: `t` proves AVX-512F.
        let root = |d: f32| unsafe { avx512::root_sum(t, &[d]) };
        // Every f32 in [1, 4) (both parities of the exponent: the estimate
        // of 1/√x is scaled by powers of 4 only), every 7th in a debug build.
        let step = if cfg!(debug_assertions) { 7 } else { 1 };
        let mut worst: f64 = 0.0;
        for bits in (1f32.to_bits()..4f32.to_bits()).step_by(step) {
            let d = f32::from_bits(bits);
            let exact = f64::from(d).sqrt();
            worst = worst.max((root(d) - exact).abs() / exact);
        }
        // Measured: within one ulp (2.2e-16 at worst), far inside the bound.
        assert!(worst < ROOT_ERROR / 16.0, "worst relative error {worst:e}");
        // Every scale of f32, subnormals to the largest; 0, +∞ and NaN.
        let mut u = crate::testing::below(5);
        for _ in 0..200_000 {
            let d = f32::from_bits(u(u64::from(f32::MAX.to_bits()) + 1) as u32);
            let exact = f64::from(d).sqrt();
            let got = root(d);
            assert!(
                (got - exact).abs() <= exact * ROOT_ERROR / 16.0,
                "{d:e}: {got} {exact}"
            );
        }
        assert_eq!(root(0.0), 0.0);
        assert_eq!(root(f32::INFINITY), f64::INFINITY);
        assert!(root(f32::NAN).is_nan());
        // SAFETY: as above.
        assert_eq!(unsafe { avx512::root_sum(t, &[]) }, 0.0);
    }

    /// PCL's d̄_i: sorted, the first skipped, summed nearest first.
    fn in_pcl_order(nearest: &[f32], mean_k: usize) -> f32 {
        let mut sorted = nearest.to_vec();
        sorted.sort_unstable_by(f32::total_cmp);
        let sum = sorted[1..]
            .iter()
            .fold(0.0_f64, |s, &d| s + f64::from(d).sqrt());
        (sum / mean_k as f64) as f32
    }

    #[test]
    fn the_mean_in_any_order_is_pcls_to_the_bit() {
        // Shuffled distances of every scale from 1e-12 to 1e4 m², k from 1 to 100.
        let mut s = 7u64;
        let mut u = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64) / (1u64 << 53) as f64
        };
        for trial in 0..100_000 {
            let k = [1, 2, 5, 20, 50, 51, 100][trial % 7];
            let scale = 10f64.powi((trial % 17) as i32 - 12);
            let mut d: Vec<f32> = (0..k).map(|_| (u() * scale) as f32).collect();
            d.push(0.0);
            d.rotate_right(trial % (k + 1));
            for isa in Isa::available() {
                assert_eq!(
                    mean_of_on(isa, &d, k).to_bits(),
                    in_pcl_order(&d, k).to_bits(),
                    "{isa:?} {d:?}"
                );
            }
        }
    }
}
