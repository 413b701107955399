//! Errors of travel planning and scenario loading.

use std::path::PathBuf;

use autoshovel_core::Vec2;

/// Everything that can go wrong when loading a map or planning a path.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PropelError {
    /// A scenario file could not be read.
    #[error("cannot read scenario file {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A scenario file is not valid TOML or has wrong or missing fields.
    #[error("{file}:{line}:{column}: {message}")]
    Parse {
        /// The file (or `<builtin>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value in a scenario is out of range or inconsistent.
    #[error("{file}:{line}: {what}")]
    Invalid {
        /// The file (or `<builtin>`).
        file: String,
        /// 1-based line of the table holding the value (0 when unknown).
        line: usize,
        /// What is wrong, naming the value.
        what: String,
    },
    /// An unknown built-in scenario name that is not a file either.
    #[error("unknown scenario '{name}': not a built-in ({known}) and no such file")]
    UnknownScenario {
        /// What the user gave.
        name: String,
        /// The built-in names.
        known: String,
    },
    /// A start, midpoint or goal that the machine cannot stand on.
    #[error("{which} ({x:.3}, {y:.3}) is {why}")]
    BadPose {
        /// "start", "midpoint" or "goal".
        which: &'static str,
        /// East [m].
        x: f64,
        /// North [m].
        y: f64,
        /// e.g. "inside obstacle 'truck' (clearance -0.400 m)".
        why: String,
    },
    /// The potential-field descent stopped making progress.
    #[error(
        "local minimum at ({x:.3}, {y:.3}) after {iterations} steps, {distance_to_goal_m:.3} m from the goal of leg {leg} ({escapes} escape attempts)"
    )]
    LocalMinimum {
        /// East [m].
        x: f64,
        /// North [m].
        y: f64,
        /// Leg index (0-based).
        leg: usize,
        /// Steps taken.
        iterations: usize,
        /// Remaining straight-line distance [m].
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
        /// East [m].
        x: f64,
        /// North [m].
        y: f64,
        /// Clearance of the footprint [m] (≤ 0).
        clearance_m: f64,
        /// Name of the obstacle hit.
        obstacle: String,
    },
    /// The reference planner found no path.
    #[error("reference A* found no path: {why}")]
    NoPath {
        /// Why.
        why: String,
    },
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
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, PropelError>;
