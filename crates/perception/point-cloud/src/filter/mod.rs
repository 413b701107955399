//! The filters of the rope-shovel paper's combined filtering process (§3.2,
//! [RS eq. 13]–[RS eq. 20]), with PCL's semantics where PCL has the filter, so that a
//! cloud filtered here keeps exactly the points PCL 1.13 keeps:
//!
//! | step | function | paper | PCL / Open3D counterpart |
//! |---|---|---|---|
//! | ground removal | [`pass_through`] | §3.2, first step | `pcl::PassThrough` |
//! | radius outlier removal | [`radius_outlier_removal`] | [RS eq. 13] | `pcl::RadiusOutlierRemoval` |
//! | statistical outlier removal | [`statistical_outlier_removal`] | [RS eq. 14]–[RS eq. 16] | `pcl::StatisticalOutlierRemoval` |
//! | down-sampling to voxel centroids | [`voxel_grid`] | [RS eq. 17]–[RS eq. 18] | `pcl::VoxelGrid` |
//! | normals by PCA | [`estimate_normals`] | §3.2, before [RS eq. 19] | `pcl::NormalEstimation` |
//! | bilateral smoothing along normals | [`bilateral_normal_smoothing`] | [RS eq. 19]–[RS eq. 20] | none in PCL's filters or in Open3D |
//! | selection by attribute ranges | [`range_indices`] | not in the papers (a classified survey's ground) | PDAL `filters.range` |
//!
//! Every filter is a free function taking the cloud and a plain parameter
//! struct with a `Default`; the removal filters also come as `*_indices`
//! functions returning the kept indices in input order. Parameters are
//! validated first ([`CloudError::BadParameter`](crate::CloudError::BadParameter)
//! naming the value); an empty input, or a filter that removes every point,
//! is [`CloudError::Emptied`](crate::CloudError::Emptied) with a hint of
//! what to change. Non-finite points are dropped by every filter, as PCL's
//! tools do. Neighbour searches build one index per call and query it in
//! parallel with rayon: a grid of height-sorted columns for a dense scan
//! (`search::columns`: statistical and radius removal, smoothing), an octree for the
//! statistical filter where the density varies widely across the cloud
//! (`search::octree`), a k-d tree for normals and for clouds too sparse for a
//! grid (`search::kdtree`, which says why it is not `kiddo`); all find the same
//! neighbours, and results never depend on the number of threads.

mod bilateral;
mod common;
mod exp;
mod normals;
mod pass_through;
mod radius_outlier;
mod range;
mod statistical_outlier;
mod voxel_grid;

pub use bilateral::{bilateral_normal_smoothing, BilateralParams};
pub use normals::{estimate_normals, Neighbourhood, NormalParams, Orientation};
pub use pass_through::{pass_through, pass_through_indices, Axis, PassThroughParams};
pub use radius_outlier::{
    radius_outlier_removal, radius_outlier_removal_indices, radius_outlier_removal_then,
    RadiusKept, RadiusOutlierParams,
};
pub use range::{range_indices, Range, RangeLimits};
pub use statistical_outlier::{
    mean_distances_and_reach, mean_distances_and_reach_at, statistical_outlier_removal,
    statistical_outlier_removal_indices, DistanceSums, OutlierCut, OutlierSides,
    StatisticalOutlierParams,
};
pub use voxel_grid::{voxel_grid, voxel_grid_nearest, VoxelCells, VoxelGridParams};
