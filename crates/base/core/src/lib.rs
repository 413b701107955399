//! Shared foundation of autoshovel: plane geometry aliases, poses and frame
//! conventions (SPEC §1), angle wrapping, polylines, cubic B-splines and
//! product-of-exponentials twists ([`poe`]), TOML configuration files
//! with located errors ([`config`]), and a caught panic's words.
//!
//! Every other crate depends on this one; it depends on nothing of ours.

// Units in brackets ("[m]", "[deg]") are the house style, not intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

mod angle;
mod bspline;
pub mod config;
mod geom;
mod panic;
pub mod poe;
mod polyline;

pub use angle::{angle_diff, deg, rad, wrap_angle};
pub use bspline::{CubicBSpline, CurveSample};
pub use geom::{heading_vec, perp, Pose2, Vec2};
pub use panic::panic_message;
pub use polyline::{arc_lengths, menger_curvature, polyline_length, segment_nearest};
