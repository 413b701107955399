//! Rope-shovel dig planning (rope-shovel paper §2 and §4; SPEC §4.2–4.3):
//! product-of-exponentials kinematics of the 1R-1P dipper ([`kinematics`],
//! [RS eqs. 1–8]), Lagrange dynamics with digging resistance
//! ([`dynamics`], [RS eq. 10]), the 6th-order tooth path ([`trajectory`],
//! [RS eqs. 22–24]), the pile as the planner sees it ([`dig_surface`],
//! [RS eq. 21] and [RS eq. 28]), and the planner that puts them under the
//! 18 constraints and the Grey Wolf Optimizer ([`plan`], [RS eqs. 25–37]).
//! The machine is a [`MachineProfile`] read from TOML.
//!
//! The `plan-dig` job lives here too: [`job`] (setup, pile, [`plan_pile`]
//! and its typed [`DigSummary`]), [`compare`] (the four piles beside the
//! paper's Tables 4–5, [`all_surfaces`]), [`paper`] (those tables as data),
//! [`pack`] (the warm-start `pack.csv`) and [`scan`] (the dig profile cut
//! from a perceived scan).
//!
//! The `validate-dig` job, planned against measured ([RS §5], Table 6,
//! Fig. 20), is [`validate`].

pub mod calibrate;
pub mod compare;
pub mod dig_surface;
pub mod dynamics;
mod error;
pub mod job;
pub mod kinematics;
pub mod pack;
pub mod paper;
pub mod plan;
pub mod profile;
pub mod scan;
pub mod similar;
pub mod trajectory;
pub mod validate;

pub use autoshovel_core::config::TomlFile;
pub use compare::{
    all_surfaces, table_summary, AllSurfaces, AllSurfacesSummary, ComparedPile, PaperPlanCheck,
    SurfaceComparison, TableColumn, TableRow, TableSummary, TABLE_COLUMNS,
};
pub use dig_surface::DigSurface;
pub use error::{DigError, PackProblem, PlanDirProblem, RecordProblem, Result};
pub use job::{
    plan_pile, ConstraintReport, DigHeader, DigSetup, DigSummary, Pile, PlanFields, PlannedPile,
    WarmStart, WarmStartSummary, BUILTIN_PROFILE_NAME,
};
pub use kinematics::{Joints, RopeShovel};
pub use pack::{read_pack, write_pack, PACK_COLUMNS};
pub use paper::{paper_pile, paper_row, PaperPile, PaperRow, CALIBRATION_PILE, PAPER_TABLES_4_5};
pub use plan::{
    gwo_preset, plan_dig, search_preset, Bound, ConstraintLimit, DigModel, DigOutcome, DigPlan,
    DigSample, DigSearch, SearchSpace, CONSTRAINT_NAMES, CONSTRAINT_UNITS, SAMPLE_COLUMNS,
};
pub use profile::{Geometry, MachineProfile};
pub use scan::{cut_scan, PerceptionSummary, ScanCut, ScanSource, TOE_RISE_SHARE};
pub use similar::Similarity;
pub use trajectory::{Decision, Trajectory};
