//! Crawler trajectory tracking (SPEC §3; electric-shovel paper §4–5): the
//! crawler plant with slip and motor limits, RTK sensing with noise, offset
//! and dropouts, the tracking geometry of eqs. 21–22 with signed deviations,
//! the fuzzy tracker of §4.3 with PID and pure pursuit beside it, and the
//! closed-loop runner with a safety layer and metrics.

// Units in brackets ("[m]", "[deg]") are the house style, not intra-doc links.
#![allow(rustdoc::broken_intra_doc_links)]

pub mod controller;
pub mod fuzzy_tracker;
pub mod geometry;
pub mod plant;
pub mod scenario;
pub mod sensor;
pub mod sim;

pub use controller::{ControlInput, Controller, Pid, PidParams, PurePursuit, PurePursuitParams};
pub use fuzzy_tracker::{FuzzyParams, FuzzyTracker};
pub use geometry::{deviations, Deviations, RefLeg};
pub use plant::{Crawler, CrawlerParams, SlipParams, TrackCommand};
pub use sensor::{Rtk, RtkFix, RtkParams};
pub use sim::{simulate, Metrics, Run, Setup, SimParams};
