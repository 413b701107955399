//! Shared foundation of autoshovel: plane geometry aliases, poses and frame
//! conventions (SPEC §1), angle wrapping, polylines, cubic B-splines and
//! product-of-exponentials twists ([`poe`]), TOML configuration files
//! with located errors ([`config`]), a caught panic's words, an error's
//! causes in one line ([`error_chain`]), and what
//! several stages share: the constant of gravity ([`G`]) and a crawler's
//! direction of travel ([`Direction`]).
//!
//! Every other crate depends on this one; it depends on nothing of ours.

mod angle;
mod bspline;
mod chain;
pub mod config;
mod consts;
mod geom;
mod panic;
pub mod poe;
mod polyline;
mod travel;

pub use angle::{angle_diff, deg, rad, wrap_angle};
pub use bspline::{CubicBSpline, CurveSample};
pub use chain::{check_dir, error_chain, os_error};
pub use consts::G;
pub use geom::{heading_vec, perp, Pose2, Vec2};
pub use panic::panic_message;
pub use polyline::{arc_lengths, menger_curvature, polyline_length, segment_nearest};
pub use travel::Direction;
