//! Hydraulic-excavator two-level dig planning (SPEC §5; Shao, Ye & Sun 2016,
//! "Two-level planning method of smoothly excavating for hydraulic excavator",
//! `seeds/hydraulic-excavator-two-level-planning.zh.txt`).
//!
//! - [`kinematics`]: boom, stick and bucket by D-H, forward and inverse to the
//!   tooth tip with a digging attitude angle, joint limits (paper §1.1).
//! - [`dynamics`]: Lagrange dynamics, joint torques against the digging resistance.
//! - [`quintic`], [`volume`], [`level1`]: level 1 — quintic joint paths ([HE eq. 1]),
//!   volume by trapezoids ([HE eq. 2]), midpoint and end point by the step search (§1.2).
//! - [`obstacle`], [`soil`], [`simulate`]: envelope circles ([HE eq. 10]), the digging
//!   resistance and the simulator that meets boulders the planner does not know.
//! - [`preimage`], [`search`], [`smooth`]: level 2 — the side from the angle γ,
//!   the forward search over the free set P and collision set Q, smoothing (§2.2).
//! - [`excavation`]: both levels run against the simulator, with re-planning of the
//!   remaining volume after each boulder; [`excavation::Excavation`] holds everything
//!   to plot and summarise.
//! - [`profile`], [`scenario`]: the machine and the dig as TOML; [`setup`]
//!   loads both (built-ins by name) and runs the plan; [`summary`] is the
//!   `plan-excavate` job's typed summary.
//!
//! The dig plane is SPEC §1's: x horizontal away from the machine (origin on
//! the slew axis at ground level), y up; digging moves towards −x.
//!
//! ```
//! use autoshovel_excavator_dig::{excavate, preimage::AvoidSide, MachineProfile, Scenario};
//!
//! let plan = excavate(&Scenario::paper_over(), &MachineProfile::default())?;
//! assert!((plan.achieved_volume_m3 - 0.9).abs() < 0.02 * 0.9);
//! assert_eq!(plan.avoid_direction, Some(AvoidSide::Over));
//! # Ok::<(), autoshovel_excavator_dig::ExcavateError>(())
//! ```

pub mod dynamics;
mod error;
pub mod estimate;
pub mod excavation;
pub mod ground;
pub mod kinematics;
pub mod level1;
pub mod obstacle;
pub mod paper;
mod planner;
pub mod preimage;
pub mod profile;
pub mod quintic;
pub mod scenario;
pub mod search;
pub mod segment;
pub mod setup;
pub mod simulate;
pub mod smooth;
pub mod soil;
pub mod study;
pub mod summary;
pub mod volume;

pub use autoshovel_core::config::TomlFile;
pub use error::{ExcavateError, Result};
pub use excavation::{excavate, ContactReport, Excavation, Sample, Summary};
pub use kinematics::{Backhoe, IkError, Joint, Joints};
pub use paper::{paper_case, PaperCase, PAPER_CASES};
pub use preimage::AvoidSide;
pub use profile::MachineProfile;
pub use scenario::Scenario;
pub use setup::Setup;
pub use summary::ExcavateSummary;
