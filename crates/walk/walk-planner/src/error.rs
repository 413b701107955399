//! Errors of travel planning and scenario loading: one enum for the crate,
//! structured fields in every variant (the file and line at fault, the
//! values that broke a rule), messages that say what to change.

use std::path::PathBuf;

use autoshovel_core::config::ConfigError;
use autoshovel_core::Vec2;

use crate::map::PolygonFault;

/// Everything that can go wrong when loading a map or planning a path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PropelError {
    /// A scenario file is not valid TOML, or has unknown, missing or
    /// mistyped keys (names the file, line and column).
    /// (Boxed: keeps the error small for the crates that wrap it.)
    #[error(transparent)]
    Config(Box<ConfigError>),
    /// A scenario file could not be read.
    #[error("cannot read scenario file {}", path.display())]
    UnreadableScenario {
        /// The file.
        path: PathBuf,
        /// The cause ([`ConfigError::Io`]).
        #[source]
        source: Box<ConfigError>,
    },
    /// A number in a scenario is NaN or infinite.
    #[error("{file}:{line}: {key} has a non-finite number ({value})")]
    NonFinite {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// The table and key, e.g. `[start]: x_m` or `circle #1 'rock': radius_m`.
        key: String,
        /// The value given.
        value: f64,
    },
    /// A coordinate or length in a scenario beyond what a site may span.
    #[error("{file}:{line}: {key} has {value:e}, beyond the ±1e6 m a site may span")]
    BeyondSite {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// The table and key.
        key: String,
        /// The value given (m).
        value: f64,
    },
    /// A value in a scenario outside its range.
    #[error("{file}:{line}: {key} = {value} must be {expected}")]
    OutOfRange {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// The table and key, e.g. `footprint_radius_m` or `circle #1 'rock': radius_m`.
        key: String,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// The site's `max_m` does not exceed its `min_m`.
    #[error("{file}:{line}: [site] max_m {max_m:?} must exceed min_m {min_m:?} in x and y")]
    SiteInverted {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of `[site]`.
        line: usize,
        /// Lower corner (m).
        min_m: [f64; 2],
        /// Upper corner (m).
        max_m: [f64; 2],
    },
    /// The site is larger than a planning site may be.
    #[error("{file}:{line}: [site] spans {extent_m} m; planning sites are limited to {limit_m} m")]
    SiteTooLarge {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of `[site]`.
        line: usize,
        /// Larger side of the site (m).
        extent_m: f64,
        /// The limit (m).
        limit_m: f64,
    },
    /// A polygon obstacle that is not a convex polygon.
    #[error("{file}:{line}: {item} {fault}")]
    BadPolygon {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the `[[polygon]]`.
        line: usize,
        /// Which polygon, e.g. `polygon #1 'truck'`.
        item: String,
        /// What is wrong with it.
        fault: PolygonFault,
    },
    /// A polygon or boundary with too many or too few points.
    #[error("{file}:{line}: {item} has {count} {what}; {limit}")]
    PointCount {
        /// The file (or `<builtin …>`).
        file: String,
        /// 1-based line of the table.
        line: usize,
        /// Which element, e.g. `boundary #2 'left edge'`.
        item: String,
        /// How many it has.
        count: usize,
        /// `vertices` or `points`.
        what: &'static str,
        /// The rule, e.g. `at most 1000` or `needs at least 2`.
        limit: &'static str,
    },
    /// A planner option out of range (see [`crate::ApfParams::validate`]).
    #[error("planner option {name} = {value} is out of range")]
    BadOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
    },
    /// A random-road study asked for out of range (see
    /// [`crate::study::StudyParams::check`]).
    #[error("study-paths: {0}")]
    BadStudy(String),
    /// An unknown built-in scenario name that is not a file either.
    #[error("unknown scenario '{name}': not a built-in ({}) and no such file", known.join(", "))]
    UnknownScenario {
        /// What the user gave.
        name: String,
        /// The built-in names.
        known: Vec<&'static str>,
    },
    /// No built-in scenario has this name.
    #[error("unknown built-in scenario '{name}' (built-ins: {})", known.join(", "))]
    UnknownBuiltin {
        /// What the user gave.
        name: String,
        /// The built-in names.
        known: Vec<&'static str>,
    },
    /// A start, midpoint or goal that the machine cannot stand on.
    #[error("{which} ({x:.3}, {y:.3}) is {fault}")]
    BadPose {
        /// "start", "midpoint" or "goal".
        which: &'static str,
        /// East (m).
        x: f64,
        /// North (m).
        y: f64,
        /// Why the machine cannot take the pose.
        fault: PoseFault,
    },
    /// The potential-field descent stopped making progress.
    #[error(
        "local minimum at ({x:.3}, {y:.3}) after {iterations} steps, {distance_to_goal_m:.3} m from the goal of leg {leg} ({escapes} escape attempts)"
    )]
    LocalMinimum {
        /// East (m).
        x: f64,
        /// North (m).
        y: f64,
        /// Leg index (0-based).
        leg: usize,
        /// Steps taken.
        iterations: usize,
        /// Remaining straight-line distance (m).
        distance_to_goal_m: f64,
        /// Escapes tried before giving up.
        escapes: usize,
    },
    /// The raw or smoothed path comes closer to an obstacle than the footprint allows.
    #[error("{stage} path of leg {leg} collides near ({x:.3}, {y:.3}): footprint clearance {clearance_m:.3} m to '{obstacle}'")]
    Collision {
        /// "raw" or "smoothed".
        stage: &'static str,
        /// Leg index (0-based).
        leg: usize,
        /// East (m).
        x: f64,
        /// North (m).
        y: f64,
        /// Clearance of the footprint (m) (≤ 0).
        clearance_m: f64,
        /// Name of the obstacle hit.
        obstacle: String,
    },
    /// A path that arrives at the end of a leg off its required heading:
    /// the machine would have to turn on the spot (see [`crate::outcome::Failure`]).
    #[error(
        "the required heading cannot be met: the path arrives at {} {error_deg:.2} deg off it (tolerance {tolerance_deg} deg); the machine would have to turn on the spot",
        leg_end(*leg, *legs)
    )]
    HeadingNotMet {
        /// Leg index (0-based).
        leg: usize,
        /// Legs of the plan.
        legs: usize,
        /// Heading error at the end of the leg (deg) (NaN when unknown).
        error_deg: f64,
        /// The tolerance it exceeds (deg).
        tolerance_deg: f64,
    },
    /// The reference planner found no path.
    #[error("reference A* found no path: {fault}")]
    NoPath {
        /// Why.
        fault: NoPathFault,
    },
}

/// "the goal" for the last leg, else "the midpoint (end of leg N)".
fn leg_end(leg: usize, legs: usize) -> String {
    if leg + 1 == legs {
        "the goal".to_string()
    } else {
        format!("the midpoint (end of leg {})", leg + 1)
    }
}

/// Why the machine cannot take a start, midpoint or goal pose.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PoseFault {
    /// A coordinate or the heading is NaN or infinite.
    #[error("not finite (heading {heading_rad})")]
    NotFinite {
        /// The heading given (rad).
        heading_rad: f64,
    },
    /// Outside the site rectangle.
    #[error("outside the site [{}, {}] x [{}, {}]", min_m[0], max_m[0], min_m[1], max_m[1])]
    OutsideSite {
        /// Lower corner of the site (m).
        min_m: [f64; 2],
        /// Upper corner of the site (m).
        max_m: [f64; 2],
    },
    /// The footprint overlaps an obstacle or boundary.
    #[error("too close to '{element}': footprint clearance {clearance_m:.3} m (footprint radius {footprint_radius_m} m)")]
    TooClose {
        /// The nearest obstacle or boundary.
        element: String,
        /// Footprint clearance (m) (≤ 0).
        clearance_m: f64,
        /// Footprint radius (m).
        footprint_radius_m: f64,
    },
    /// The straight stretch along the motion heading is blocked.
    #[error(
        "reachable only by turning on the spot: heading {heading_deg:.1} deg is blocked by '{element}' within {within_m} m {}",
        if *arriving { "behind it" } else { "ahead of it" }
    )]
    HeadingBlocked {
        /// The pose's heading (deg).
        heading_deg: f64,
        /// The obstacle or boundary in the way.
        element: String,
        /// Length of the stretch checked (m).
        within_m: f64,
        /// Arriving (the stretch is behind the pose) or leaving (ahead of it).
        arriving: bool,
    },
}

/// Why the reference A* found no path.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum NoPathFault {
    /// The grid resolution is not a positive number.
    #[error("resolution_m = {resolution_m} must be positive")]
    BadResolution {
        /// The resolution given (m).
        resolution_m: f64,
    },
    /// The site needs more grid cells than allowed.
    #[error("grid of {nx} x {ny} cells exceeds max_cells {max_cells}")]
    TooManyCells {
        /// Cells along x.
        nx: usize,
        /// Cells along y.
        ny: usize,
        /// The limit.
        max_cells: usize,
    },
    /// No free cell near the start or goal.
    #[error("{which} ({x:.2}, {y:.2}) has no free cell near it")]
    NoFreeCell {
        /// "start" or "goal".
        which: &'static str,
        /// East (m).
        x: f64,
        /// North (m).
        y: f64,
    },
    /// The search ran out of cells.
    #[error("goal unreachable after expanding {expanded} cells")]
    Unreachable {
        /// Cells expanded.
        expanded: usize,
    },
}

impl From<ConfigError> for PropelError {
    fn from(e: ConfigError) -> Self {
        PropelError::Config(Box::new(e))
    }
}

impl PropelError {
    /// The point where planning failed, if the error has one.
    pub fn position(&self) -> Option<Vec2> {
        match self {
            PropelError::LocalMinimum { x, y, .. }
            | PropelError::Collision { x, y, .. }
            | PropelError::BadPose { x, y, .. } => Some(Vec2::new(*x, *y)),
            _ => None,
        }
    }

    /// Whether the descent stalled in a local minimum.
    pub fn is_local_minimum(&self) -> bool {
        matches!(self, PropelError::LocalMinimum { .. })
    }

    /// Escapes tried before a local minimum (0 for other errors).
    pub fn escapes(&self) -> usize {
        match self {
            PropelError::LocalMinimum { escapes, .. } => *escapes,
            _ => 0,
        }
    }
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, PropelError>;
