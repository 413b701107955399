//! Crawler trajectory tracking (SPEC §3; electric-shovel walking paper §4–5):
//! the crawler plant with slip and motor limits ([W eq. 16]–[W eq. 20]), RTK
//! sensing with noise, offset and dropouts, the tracking geometry of
//! [W eq. 21]–[W eq. 22] with signed deviations, the fuzzy tracker of §4.3
//! ([W eq. 23], [W eq. 24], Table 1) with PID and pure pursuit beside it, the
//! closed-loop runner with a safety layer and metrics, tracking scenarios
//! and the `track` job's typed summary.

pub mod choice;
pub mod controller;
pub mod error;
pub mod fuzzy_tracker;
pub mod geometry;
pub mod job;
pub mod machine;
pub mod plant;
pub mod scenario;
pub mod sensor;
pub mod sim;
pub mod tune;
pub mod workstation;

pub use autoshovel_core::config::TomlFile;
pub use choice::ControllerKind;
pub use controller::{
    ControlInput, Controller, ControllerParams, FuzzyParams, Gains, Pid, PidError, PidParams,
    PurePursuit, PurePursuitParams, Stanley, StanleyParams, Universe,
};
pub use error::TrackError;
pub use fuzzy_tracker::FuzzyTracker;
pub use geometry::{deviations, Deviations, PathFault, RefLeg};
pub use job::{track, ControllerRun, RunSummary, TrackParams, TrackSummary, Tracking};
pub use machine::Machine;
pub use plant::{Crawler, CrawlerParams, SlipParams, TrackCommand};
pub use scenario::{Noise, ScenarioFile, TrackScenario};
pub use sensor::{Rtk, RtkFix, RtkParams};
pub use sim::{simulate, Metrics, Run, Setup, SimParams};
pub use workstation::{Decision, Status, Tick, Workstation};
