//! Point clouds (SPEC §4.1; rope-shovel paper §3): readers and writers for
//! PCD, PLY, LAS/LAZ and XYZ/CSV (`io`), the filters of the paper's
//! combined filtering process with PCL's semantics (`filter`), the
//! neighbour searches they stand on (`search`: a grid of columns, a k-d
//! tree, an octree, and their distance kernels) and the one
//! instruction-set layer every vectorised kernel goes through ([`simd`]).
//!
//! Points are stored as `[f32; 3]`, as PCL, PCD, PLY and LiDAR drivers do:
//! half the memory of f64 for scans of tens of millions of points, and the
//! same arithmetic as PCL where results must agree with it. This is the one
//! place the house rule "f64 everywhere" gives way; everything computed from
//! a cloud (fits, calibration, volumes) is f64.

pub mod attributes;
mod cloud;
mod error;
pub mod filter;
pub mod georef;
pub mod io;
mod prefault;
pub(crate) mod search;
pub mod simd;
#[cfg(test)]
mod testing;

pub use attributes::{Attributes, Column, Values};
pub use cloud::{Point, PointCloud};
pub use error::{CloudError, Result};
pub use georef::{Crs, Georef, LasLayout, Unit, Viewpoint};
