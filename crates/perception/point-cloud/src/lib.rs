//! Point clouds (SPEC §4.1; rope-shovel paper §3): readers and writers for
//! PCD, PLY, LAS/LAZ and XYZ/CSV (`io`), and the filters of the paper's
//! combined filtering process with PCL's semantics (`filter`).
//!
//! Points are stored as `[f32; 3]`, as PCL, PCD, PLY and LiDAR drivers do:
//! half the memory of f64 for scans of tens of millions of points, and the
//! same arithmetic as PCL where results must agree with it. This is the one
//! place the house rule "f64 everywhere" gives way; everything computed from
//! a cloud (fits, calibration, volumes) is f64.

// Units in brackets ("[m]") are the house style, not intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

mod cloud;
mod error;
pub mod filter;
pub mod io;
mod room;

pub use cloud::{Point, PointCloud};
pub use error::{CloudError, Result};
