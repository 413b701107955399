//! The one error type of the crate: everything that can be wrong with a
//! problem's bounds, the optimiser's parameters, a warm start, or a value
//! the problem returns, each variant naming the value at fault.
//!
//! Everything is checked by [`crate::minimize`] before the first
//! evaluation, except the evaluations themselves, which are checked as they
//! arrive (Mirjalili et al. 2014 leave validity to the user; a planner that
//! runs unattended must not carry a NaN into the leaders).

use thiserror::Error;

/// Everything that can go wrong setting up or running the optimiser.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OptimError {
    /// The problem has no dimensions.
    #[error("the problem has no dimensions: bounds() returned an empty slice")]
    EmptyBounds,
    /// A bound pair is reversed, empty or not finite.
    #[error(
        "dimension {dim}: bounds [{lower}, {upper}] need finite lower < upper; \
         fix the problem's bounds()"
    )]
    BadBounds {
        /// Index of the dimension (0-based).
        dim: usize,
        /// Lower bound as given.
        lower: f64,
        /// Upper bound as given.
        upper: f64,
    },
    /// Fewer wolves than the three leaders plus one.
    #[error("population {population} is too small: GWO needs α, β, δ and at least one ω (≥ 4)")]
    PopulationTooSmall {
        /// The requested population.
        population: usize,
    },
    /// A CMA-ES step share out of range.
    #[error("CMA-ES {name} = {value}: expected a share of the box width in (0, 1]")]
    BadStep {
        /// `initial_step` or `min_step`.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// No iterations requested.
    #[error("iterations is 0: ask for at least one position update")]
    ZeroIterations,
    /// A penalty weight that is negative or not finite.
    #[error("penalty weight {weight} must be finite and ≥ 0")]
    BadPenaltyWeight {
        /// The weight given.
        weight: f64,
    },
    /// More warm-start wolves than the population holds.
    #[error("{given} warm-start wolves do not fit a population of {population}")]
    TooManyWarmStarts {
        /// Number of warm-start wolves given.
        given: usize,
        /// The population size.
        population: usize,
    },
    /// A warm-start wolf of the wrong dimension.
    #[error("warm-start wolf {wolf} has {got} coordinate(s), the problem has {expected}")]
    WarmStartDimension {
        /// Index of the wolf in the warm-start list.
        wolf: usize,
        /// Dimension of the problem.
        expected: usize,
        /// Length of the wolf given.
        got: usize,
    },
    /// A warm-start coordinate is NaN or infinite.
    #[error("warm-start wolf {wolf}, dimension {dim}: coordinate {value} is not finite")]
    WarmStartNotFinite {
        /// Index of the wolf in the warm-start list.
        wolf: usize,
        /// Index of the coordinate.
        dim: usize,
        /// The value given.
        value: f64,
    },
    /// The problem returned a NaN objective.
    #[error(
        "the objective is NaN at iteration {iteration} (0 = initial population), wolf {wolf}, \
         x = {x:?}; return a finite or infinite value, never NaN"
    )]
    NanObjective {
        /// Iteration (0 for the initial population, then 1 ..= iterations).
        iteration: usize,
        /// Index of the wolf in the population.
        wolf: usize,
        /// The position evaluated.
        x: Vec<f64>,
    },
    /// The problem returned a violation that is NaN or negative.
    #[error(
        "the constraint violation {violation} at iteration {iteration} (0 = initial population), \
         wolf {wolf}, x = {x:?} is not ≥ 0; return the sum of max(0, c_i)"
    )]
    BadViolation {
        /// Iteration (0 for the initial population, then 1 ..= iterations).
        iteration: usize,
        /// Index of the wolf in the population.
        wolf: usize,
        /// The violation returned.
        violation: f64,
        /// The position evaluated.
        x: Vec<f64>,
    },
}
