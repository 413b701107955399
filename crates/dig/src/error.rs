//! Errors of dig planning and machine-profile loading.

use std::path::PathBuf;

/// Everything that can go wrong when loading a profile or planning a dig.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DigError {
    /// A profile file could not be read.
    #[error("cannot read machine profile {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A profile is not valid TOML, or has unknown or missing keys.
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
    /// A value in a profile is out of range or contradicts another.
    #[error("{file}:{line}: {key} = {value} is invalid: expected {expected}")]
    Invalid {
        /// The file (or `<builtin>`).
        file: String,
        /// 1-based line of the key (0 when unknown).
        line: usize,
        /// `[table] key`.
        key: String,
        /// The value given.
        value: f64,
        /// What it should be.
        expected: String,
    },
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
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, DigError>;
