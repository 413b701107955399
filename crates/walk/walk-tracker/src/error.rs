//! The crate's one error type, [`TrackError`]: loading a tracking scenario
//! (naming the file, line, key and value at fault), planning its path, and a
//! run that did not complete.

use autoshovel_core::config::ConfigError;
use autoshovel_walk_planner::PropelError;

use crate::geometry::PathFault;

/// Everything that can go wrong when loading a tracking scenario or running it.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TrackError {
    /// A scenario file could not be read or parsed, or a value is out of
    /// range (names the file, line, key and value).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Neither a built-in nor an existing file.
    #[error("unknown tracking scenario '{name}': not a built-in ({known}) and no such file")]
    UnknownScenario {
        /// What was given.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A value that must be a finite number is not.
    #[error("{file}:{line}: {key} = {value} is not a finite number")]
    NotFinite {
        /// The file.
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// `[table] key`.
        key: String,
        /// The value given.
        value: f64,
    },
    /// A `[[leg]]` of the file cannot be tracked.
    #[error("{file}:{line}: [[leg]] #{leg} points_m {fault}")]
    Leg {
        /// The file.
        file: String,
        /// 1-based line of the leg's `points_m` (0 when unknown).
        line: usize,
        /// 1-based number of the leg.
        leg: usize,
        /// What is wrong with its points.
        fault: PathFault,
    },
    /// A leg planned from a travel scenario cannot be tracked.
    #[error("{file}: planned leg #{leg} {fault}")]
    PlannedLeg {
        /// The travel scenario.
        file: String,
        /// 1-based number of the leg.
        leg: usize,
        /// What is wrong with its points.
        fault: PathFault,
    },
    /// The start is too far from the first leg to be tracked onto it.
    #[error(
        "{file}:{line}: the start is {distance_m:.2} m from the first leg; \
         at most {max_m} m (plan a path to it first)"
    )]
    StartOffPath {
        /// The file.
        file: String,
        /// 1-based line of `[start]`'s `x_m` (0 when unknown).
        line: usize,
        /// Distance of the start from the first leg (m).
        distance_m: f64,
        /// The largest distance allowed (m).
        max_m: f64,
    },
    /// A travel scenario (a file with `[site]`) could not be loaded.
    #[error(transparent)]
    Travel(PropelError),
    /// Planning the travel scenario's path failed.
    #[error("{file}: planning the path failed: {source}")]
    Plan {
        /// The travel scenario.
        file: String,
        /// The planner's error.
        source: PropelError,
    },
    /// The controller did not bring the machine to the path's end.
    #[error("{controller} did not complete scenario '{scenario}': {why}")]
    NotCompleted {
        /// The controller's name.
        controller: String,
        /// The scenario's name.
        scenario: String,
        /// The last safety or runner event, or "did not finish".
        why: String,
    },
}
