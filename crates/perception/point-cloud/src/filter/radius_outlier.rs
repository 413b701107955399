//! Radius outlier removal ([RS eq. 13]): a point is kept when
//! at least `min_neighbors` other points lie within the Euclidean distance
//! `K_s` (`radius_m`) of it, d(p_i, p_j) ≤ K_s.
//!
//! Semantics of PCL 1.13.0's `pcl::RadiusOutlierRemoval<PointT>`, followed to
//! the bit (`filters/include/pcl/filters/impl/radius_outlier_removal.hpp`,
//! `applyFilterIndices`, the branch for dense clouds, which is the one PCL's
//! `pcl_outlier_removal` tool takes after `removeNaNFromPointCloud`):
//!
//! ```text
//! // Note: k includes the query point, so is always at least 1
//! int mean_k = min_pts_radius_ + 1;
//! double nn_dists_max = search_radius_ * search_radius_;
//! int k = searcher_->nearestKSearch (index, mean_k, nn_indices, nn_dists);
//! bool chk_neighbors = true;
//! if (k == mean_k) { ... if (nn_dists_max < nn_dists[k-1]) chk_neighbors = false; }
//! else chk_neighbors = false;
//! ```
//!
//! So a point is kept when its `(min_neighbors + 1)`-th nearest point,
//! counting itself (or a duplicate of itself) as the first, has a squared
//! distance `d` with `(double) d <= radius * radius` (the radius squared in
//! f64, as PCL does; `d` is FLANN's f32 squared distance, computed here in
//! the same order, see `search::kdtree`). Points at exactly the radius count.
//! The non-dense branch (`radiusSearch`, `k <= min_pts_radius_` removed)
//! counts the same neighbours. Non-finite points are dropped first, as the
//! PCL tool does. `radius_m` must be positive (PCL refuses 0).
//!
//! The PCL 1.13 `pcl_outlier_removal -method radius -radius R -min_pts N`
//! keeps exactly what `RadiusOutlierParams { radius_m: R, min_neighbors: N }`
//! keeps (tests/filter_pcl_agreement.rs). Open3D 0.20's
//! `remove_radius_outlier(nb_points = N, radius)` keeps a point when its
//! radius search (which counts the point itself) finds more than N points,
//! the same rule as ours with `min_neighbors = N`, but in f64 and without
//! the points at exactly the radius (on `tests/data/filters/grid.pcd`,
//! r = 0.25, N = 6 it keeps 400 points where PCL and we keep 620).

use autoshovel_core::config::short;
use rayon::prelude::*;

use super::common::{bad, emptied, empty_input, f32_at_most, gather, is_finite, on_finite_points};
use super::statistical_outlier::{
    statistical_kept_on, statistical_outlier_removal_indices, StatisticalOutlierParams,
};
use crate::search::columns::{radius_side, ColumnGrid};
use crate::search::kdtree::KdTree;
use crate::{Point, PointCloud, Result};
use serde::{Deserialize, Serialize};

const FILTER: &str = "radius outlier removal";

/// Parameters of [`radius_outlier_removal`] ([RS eq. 13]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RadiusOutlierParams {
    /// The search radius K_s (m), inclusive.
    pub radius_m: f64,
    /// The least number of other points within the radius for a point to be
    /// kept (PCL's `min_pts_radius_`, `-min_pts`).
    pub min_neighbors: usize,
}

impl Default for RadiusOutlierParams {
    /// The paper gives no values: 5 neighbours within 5 cm (documented choice)
    /// suits a full-size pile scanned at 1–3 cm spacing.
    fn default() -> Self {
        Self {
            radius_m: 0.05,
            min_neighbors: 5,
        }
    }
}

impl RadiusOutlierParams {
    fn validate(&self) -> Result<()> {
        if !(self.radius_m.is_finite() && self.radius_m > 0.0) {
            return Err(bad(
                FILTER,
                format!(
                    "radius_m must be positive and finite, got {}",
                    short(self.radius_m)
                ),
            ));
        }
        if self.min_neighbors >= u32::MAX as usize {
            return Err(bad(
                FILTER,
                format!("min_neighbors = {} is beyond any cloud", self.min_neighbors),
            ));
        }
        Ok(())
    }
}

const HINT: &str = "lower min_neighbors or raise radius_m";

/// Indices of the points kept by radius outlier removal, in input order.
pub fn radius_outlier_removal_indices(
    cloud: &[Point],
    params: &RadiusOutlierParams,
) -> Result<Vec<usize>> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let kept = on_finite_points(cloud, |points| Ok(kept_indices(points, params)))?;
    if kept.is_empty() {
        return Err(emptied(FILTER, cloud.len(), HINT));
    }
    Ok(kept)
}

/// The points kept by radius outlier removal ([RS eq. 13]), in input order.
///
/// ```
/// use autoshovel_point_cloud::{filter, PointCloud};
/// // Three points 1 m apart on a line, and a lone one.
/// let cloud = PointCloud::new(vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [9.0, 0.0, 0.0]]);
/// let params = filter::RadiusOutlierParams { radius_m: 1.0, min_neighbors: 1 };
/// let kept = filter::radius_outlier_removal(&cloud, &params).unwrap();
/// assert_eq!(kept.len(), 3); // neighbours at exactly the radius count
/// let params = filter::RadiusOutlierParams { radius_m: 1.0, min_neighbors: 2 };
/// assert_eq!(filter::radius_outlier_removal(&cloud, &params).unwrap().points, vec![[1.0, 0.0, 0.0]]);
/// ```
pub fn radius_outlier_removal(cloud: &[Point], params: &RadiusOutlierParams) -> Result<PointCloud> {
    let kept = radius_outlier_removal_indices(cloud, params)?;
    Ok(gather(cloud, &kept))
}

/// What [`radius_outlier_removal_then`] kept, with the neighbour index it
/// searched, for [`RadiusKept::statistical_indices`] to search again.
pub struct RadiusKept {
    /// Indices of the points kept, in input order (those of
    /// [`radius_outlier_removal_indices`]).
    pub kept: Vec<usize>,
    /// The grid of the kept points (by their indices in the cloud), when
    /// the cloud suited one sized for both searches.
    grid: Option<ColumnGrid>,
}

/// Radius outlier removal ([RS eq. 13]) that keeps its neighbour index for
/// the statistical filter to run on its output next ([RS eq. 14]–[RS eq. 16],
/// `mean_k` neighbours), as the paper's filtering does: the same points
/// as [`radius_outlier_removal_indices`], then (by
/// [`RadiusKept::statistical_indices`]) as
/// [`statistical_outlier_removal_indices`]
/// on them, bit for bit; but the points are filed on a grid once, with
/// columns as the k nearest want them (at least as wide as the radius),
/// and the removed ones dropped from it rather than the kept ones filed
/// again. A cloud that suits no such grid (sparse, or a radius far wider
/// than the k nearest reach, or with non-finite points) takes the two
/// filters' own paths.
pub fn radius_outlier_removal_then(
    cloud: &[Point],
    params: &RadiusOutlierParams,
    mean_k: usize,
) -> Result<RadiusKept> {
    params.validate()?;
    if cloud.is_empty() {
        return Err(empty_input(FILTER));
    }
    let wanted = params.min_neighbors + 1;
    let r2 = f32_at_most(params.radius_m * params.radius_m);
    let grid = (params.min_neighbors > 0 && wanted <= cloud.len() && cloud.iter().all(is_finite))
        .then(|| {
            let side = radius_side(f64::from(r2).sqrt());
            ColumnGrid::for_k_nearest_at_least(cloud, mean_k.saturating_add(1), side)
        })
        .flatten();
    let Some(grid) = grid else {
        return Ok(RadiusKept {
            kept: radius_outlier_removal_indices(cloud, params)?,
            grid: None,
        });
    };
    // [RS eq. 13] as in `kept_indices`, by sorted position for `retain`.
    let keep = grid.map_has_within_in_grid_order(r2, wanted);
    let kept = grid.kept_inputs(&keep);
    if kept.is_empty() {
        return Err(emptied(FILTER, cloud.len(), HINT));
    }
    Ok(RadiusKept {
        kept,
        grid: Some(grid.retain(&keep)),
    })
}

impl std::fmt::Debug for RadiusKept {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RadiusKept")
            .field("kept", &self.kept.len())
            .field("index_shared", &self.grid.is_some())
            .finish()
    }
}

impl RadiusKept {
    /// Statistical outlier removal ([RS eq. 14]–[RS eq. 16]) of the points
    /// kept, `kept_points` (the cloud's points at `kept`, in order): the
    /// indices into them that
    /// [`statistical_outlier_removal_indices`]
    /// gives, from the index the radius filter searched when it kept one.
    pub fn statistical_indices(
        self,
        kept_points: &[Point],
        params: &StatisticalOutlierParams,
    ) -> Result<Vec<usize>> {
        assert_eq!(
            kept_points.len(),
            self.kept.len(),
            "the points the radius filter kept"
        );
        match self.grid {
            Some(grid) => statistical_kept_on(&grid, &self.kept, params),
            None => statistical_outlier_removal_indices(kept_points, params),
        }
    }
}

/// The kept indices of `points` (all finite, not empty).
fn kept_indices(points: &[crate::Point], params: &RadiusOutlierParams) -> Vec<usize> {
    // [RS eq. 13]: kept when at least min_neighbors others lie within the radius.
    let wanted = params.min_neighbors + 1; // the point itself comes first
    if params.min_neighbors == 0 {
        return (0..points.len()).collect();
    }
    if wanted > points.len() {
        return Vec::new();
    }
    let r2 = f32_at_most(params.radius_m * params.radius_m);
    // The wanted-th nearest is within the radius exactly when at least
    // `wanted` points are: count them, stopping at `wanted` (on a grid of
    // columns as wide as the radius when the cloud suits one, `search::columns`;
    // else on the k-d tree: the same counts).
    match ColumnGrid::for_radius(points, f64::from(r2).sqrt()) {
        Some(grid) => grid.kept_inputs(&grid.map_has_within_in_grid_order(r2, wanted)),
        None => {
            let tree = KdTree::new(points);
            indices_of(&tree.map_points(|| (), |_, _, p| tree.has_within(p, r2, wanted)))
        }
    }
}

/// The positions of the `true`s.
fn indices_of(keep: &[bool]) -> Vec<usize> {
    keep.par_iter()
        .enumerate()
        .filter(|(_, &k)| k)
        .map(|(i, _)| i)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scan of a wavy surface, 1 cm noise, 2 % of points flung up to
    /// 0.5 m above it.
    fn scan(n: usize, seed: u64) -> Vec<Point> {
        let mut u = crate::testing::uniform(seed);
        (0..n)
            .map(|i| {
                let (x, y) = (u() * 20.0, u() * 20.0);
                let lift = if i % 50 == 0 { u() * 0.5 } else { 0.0 };
                [x, y, (0.3 * x).sin() + 0.1 * y + 0.01 * u() + lift]
            })
            .collect()
    }

    #[test]
    fn the_shared_grid_keeps_what_the_two_filters_keep() {
        // On a scan the index is shared (the radius within the k nearest's
        // reach), and the result is the two filters', bit for bit.
        let points = scan(60_000, 5);
        for (radius_m, min_neighbors, mean_k) in [(0.1, 3, 20), (0.2, 5, 8), (0.05, 1, 50)] {
            let radius = RadiusOutlierParams {
                radius_m,
                min_neighbors,
            };
            let statistical = StatisticalOutlierParams {
                mean_k,
                std_mul: 1.0,
                ..Default::default()
            };
            let first = radius_outlier_removal_then(&points, &radius, mean_k).unwrap();
            assert!(first.grid.is_some(), "{radius_m} {mean_k}");
            let kept = radius_outlier_removal_indices(&points, &radius).unwrap();
            assert_eq!(first.kept, kept);
            let kept_points: Vec<Point> = kept.iter().map(|&i| points[i]).collect();
            let want = statistical_outlier_removal_indices(&kept_points, &statistical).unwrap();
            assert!(want.len() < kept.len());
            assert_eq!(
                first
                    .statistical_indices(&kept_points, &statistical)
                    .unwrap(),
                want
            );
        }
        // A radius far beyond the k nearest's reach: the filters' own paths.
        let radius = RadiusOutlierParams {
            radius_m: 3.0,
            min_neighbors: 3,
        };
        assert!(radius_outlier_removal_then(&points, &radius, 20)
            .unwrap()
            .grid
            .is_none());
    }
}
