//! autoshovel's jobs as its front ends run them: the command line, the
//! demo and the Python bindings. A job is one library call (the method
//! lives in its own crate: `autoshovel-walk-planner`, `-walk-tracker`,
//! `-terrain`, `-rope-shovel-dig`, `-excavator-dig`, `-work-shift`,
//! `-plc-link`), then its figures
//! (`autoshovel-figures`) written into the output folder under the output
//! rule, as a [`Job`] of the typed summary and the files written.
//!
//! Nothing here decides a result: the checks are of a job's settings, said
//! in the names the front ends give them.

pub mod demo;
mod dig;
mod error;
mod filter;
mod job;
pub mod process;
mod scan;
mod walk;

pub use dig::{
    plan_dig, plan_dig_all_surfaces, plan_excavate, shift, study_boulders, validate_dig,
};
pub use error::{JobError, Result};
pub use filter::{filter, write_cloud};
pub use job::{out_dir, progress_bar, Job, OutDir, Staging, Written};
pub use scan::{perceive, perceive_frames, perceive_tiles, read_and_perceive, scan_pile};
pub use walk::{drive, plan_path, replay, runtime, study, track, tune_trackers};
