//! Errors of dig planning and machine-profile loading.

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
}

/// Shorthand for results of this crate.
pub type Result<T> = std::result::Result<T, DigError>;
