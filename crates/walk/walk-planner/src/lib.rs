//! Travel (propel) planning for crawler excavators (SPEC §2; electric-shovel
//! paper §2–3): a site map of obstacles and road boundaries, the classic and
//! improved artificial potential fields, cubic B-spline smoothing with a
//! clearance check, straight / curve / V-shaped moves as legs with a
//! direction, and a grid A* reference planner to judge path quality.
//!
//! ```
//! use autoshovel_walk_planner::{plan_path, FieldKind, PlanOptions, Scenario};
//! let scenario = Scenario::builtin("curve").unwrap();
//! let plan = plan_path(&scenario, &PlanOptions::new(FieldKind::Improved)).unwrap();
//! assert!(plan.metrics.final_heading_error_deg <= 2.0);
//! assert!(plan.metrics.min_clearance_m > 0.0);
//! ```

pub mod apf;
pub mod astar;
mod error;
pub mod map;
pub mod outcome;
pub mod path;
pub mod plan;
pub mod scenario;
pub mod smooth;
pub mod study;

pub use apf::{ApfParams, FieldKind};
pub use astar::{astar, AstarParams, Route};
pub use error::{NoPathFault, PoseFault};
pub use error::{PropelError, Result};
pub use map::{Boundary, Map, Obstacle, Shape};
pub use outcome::{
    reference_comparison, Failure, PlanOutcome, PlanPathSummary, ReferenceComparison,
    DEFAULT_HEADING_TOLERANCE_DEG,
};
pub use path::{Direction, Leg, Path, PathPoint};
pub use plan::{plan_path, LegStats, Plan, PlanMetrics, PlanOptions};
pub use scenario::Scenario;
pub use smooth::SmoothParams;
