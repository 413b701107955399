//! The whole machine (SPEC §9): a shift of a rope shovel at full size
//! against a world that changes. At each stand the machine repeats scan →
//! perceive ([`autoshovel_terrain`]) → plan the dig with a warm start from
//! the last ([`autoshovel_rope_shovel_dig`], on the 1:30 model scaled by
//! [`autoshovel_rope_shovel_dig::Similarity`]) → dig → swing → dump → return; when no
//! feasible dig remains it chooses the next stand from what it has
//! perceived, builds the walking map from its scans, plans the walk
//! ([`autoshovel_walk_planner`], a V-shaped move when the stand lies to the
//! side) and drives it ([`autoshovel_walk_tracker`], with slip and RTK noise).
//!
//! The code is split along the line between what the machine can know
//! and what only the simulator knows: [`world`] is the truth (the pit's
//! heights, the LiDAR that scans it, the dipper that cuts it); [`machine`]
//! is the machine's side (its pile model from scans, its dig directions,
//! its next stand, its walking map), which reads the world only through
//! scans and its RTK pose; [`run`] joins them and keeps the timeline, the
//! mass balance and the figures of merit; [`cycle`] holds the swing,
//! dump and energy models.

pub mod cycle;
mod error;
pub mod grid;
pub mod machine;
pub mod record;
pub mod run;
pub mod scenario;
pub mod world;

pub use autoshovel_core::config::TomlFile;
pub use error::{Result, ShiftError};
pub use grid::{Cut, Layout};
pub use record::{Event, PassRecord, ShiftRun, ShiftSummary, StandRecord, WalkRecord};
pub use run::{run_shift, ShiftOptions};
pub use scenario::ShiftScenario;
pub use world::{Lidar, World};
