//! Errors of dig planning, machine-profile and warm-start pack loading.

use std::path::{Path, PathBuf};

/// Everything that can go wrong when loading a profile or planning a dig.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DigError {
    /// A profile file could not be read, parsed or checked (names the file,
    /// line and key).
    #[error(transparent)]
    Config(#[from] autoshovel_core::config::ConfigError),
    /// The machine cannot put its tooth tip where the plan needs it.
    #[error("unreachable: {0}")]
    Unreachable(String),
    /// The pile surface cannot be used for a dig (too small, not rising, no toe).
    #[error("unusable pile surface: {0}")]
    Surface(String),
    /// The optimiser found no plan meeting every constraint.
    #[error(
        "no feasible dig plan after {evaluations} evaluations; the best plan still violates: {binding}"
    )]
    Infeasible {
        /// The constraints the best plan violates, with their values and limits.
        binding: String,
        /// Objective evaluations spent.
        evaluations: usize,
    },
    /// The optimiser refused its input.
    #[error(transparent)]
    Optim(#[from] autoshovel_optim::OptimError),
    /// A warm-start pack file could not be read.
    #[error("cannot read warm-start pack {}", .path.display())]
    PackRead {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A warm-start pack file could not be written.
    #[error("cannot write warm-start pack {}", .path.display())]
    PackWrite {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A warm-start pack file is not one `write_pack` wrote.
    #[error("{}: {problem}", location(.path, *.line))]
    Pack {
        /// The file.
        path: PathBuf,
        /// The 1-based line at fault, if one is.
        line: Option<usize>,
        /// What is wrong there.
        problem: PackProblem,
    },
    /// A scan whose fitted surface never rises above its floor.
    #[error(
        "{}: the scan does not rise above the floor (z = {floor_height_m:.4} m); no pile to dig",
        .path.display()
    )]
    ScanHasNoPile {
        /// The scan.
        path: PathBuf,
        /// The floor height found by perception [m].
        floor_height_m: f64,
    },
    /// The fitted surface of a scan cannot be cut into a dig profile.
    #[error(
        "{}: cutting the fitted surface along the dig plane y = {dig_plane_y_m:.4} m",
        .path.display()
    )]
    ScanCut {
        /// The scan.
        path: PathBuf,
        /// The dig plane [m].
        dig_plane_y_m: f64,
        /// Why the cut failed.
        source: Box<DigError>,
    },
    /// The machine cannot dig this pile at all (a model of the two cannot be
    /// set up), with the pile's hint when it has one.
    #[error("{pile} pile ({surface_source}): {cause}{}", note(.hint))]
    Pile {
        /// The pile's name ("typical", …, "cloud").
        pile: String,
        /// Where its profile came from.
        surface_source: String,
        /// Why the model refused it (part of this message, so not a
        /// `source` printed again after it).
        cause: Box<DigError>,
        /// Why a plan on this pile may fail (e.g. a full-size scan for a scale model).
        hint: Option<String>,
    },
}

/// What is wrong in a warm-start pack file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PackProblem {
    /// The file is empty.
    #[error("empty file; expected a pack.csv of plan-dig")]
    Empty,
    /// The header is not the pack's columns.
    #[error("header '{found}' is not a plan-dig pack (expected {expected})")]
    Header {
        /// The header found.
        found: String,
        /// The header a pack has.
        expected: String,
    },
    /// A row with the wrong number of cells.
    #[error("{found} values, expected {expected}")]
    Width {
        /// Cells found.
        found: usize,
        /// Cells a row has.
        expected: usize,
    },
    /// A cell that is not a finite number.
    #[error("{column} = '{cell}' is not a finite number")]
    NotANumber {
        /// Its column.
        column: &'static str,
        /// Its text.
        cell: String,
    },
    /// A dig duration that is not positive.
    #[error("td_s = {td_s} must be > 0")]
    DurationNotPositive {
        /// The duration read [s].
        td_s: f64,
    },
    /// A header and no wolves.
    #[error("no wolves in the pack")]
    NoWolves,
}

/// `path:line` or `path`.
fn location(path: &Path, line: Option<usize>) -> String {
    match line {
        Some(l) => format!("{}:{l}", path.display()),
        None => path.display().to_string(),
    }
}

/// "\nnote: …" for a hint, nothing without one.
fn note(hint: &Option<String>) -> String {
    hint.as_ref()
        .map(|h| format!("\nnote: {h}"))
        .unwrap_or_default()
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, DigError>;
