//! What the optimiser minimises: a box-bounded objective with an optional
//! total constraint violation, as one small trait ([`Problem`]) and a
//! wrapper for closures ([`FnProblem`]).
//!
//! Constraints g_i(x) ≤ 0 enter as one number, the total violation
//! Σ max(0, g_i(x)) (Deb 2000, "An efficient constraint handling method for
//! genetic algorithms", Comput. Methods Appl. Mech. Eng. 186:311–338);
//! how it is weighed against the objective is chosen by
//! [`crate::Constraints`].

use serde::Serialize;

use crate::error::OptimError;

/// A box-bounded minimisation problem.
///
/// `Sync` so that [`crate::minimize`] can evaluate the wolves on several
/// threads.
pub trait Problem: Sync {
    /// Box bounds, one `(lower, upper)` per dimension; the dimension is
    /// `bounds().len()`. Each pair must be finite with `lower < upper`.
    fn bounds(&self) -> &[(f64, f64)];

    /// Objective (to minimise) and total constraint violation (0 when
    /// feasible; the sum of max(0, c_i) as the caller defines it) at `x`,
    /// which always has `bounds().len()` coordinates inside the bounds.
    fn evaluate(&self, x: &[f64]) -> Evaluation;
}

/// The value of a problem at one point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Evaluation {
    /// Objective to minimise; may be infinite, never NaN.
    pub objective: f64,
    /// Total constraint violation, ≥ 0; exactly 0 means feasible.
    pub violation: f64,
}

impl Evaluation {
    /// An evaluation with the given objective and violation.
    pub fn new(objective: f64, violation: f64) -> Self {
        Self {
            objective,
            violation,
        }
    }

    /// A feasible evaluation (violation 0), for unconstrained problems.
    pub fn feasible(objective: f64) -> Self {
        Self::new(objective, 0.0)
    }

    /// Whether the point satisfies every constraint (violation exactly 0).
    pub fn is_feasible(&self) -> bool {
        self.violation == 0.0
    }
}

/// A [`Problem`] made of bounds and a closure.
///
/// ```
/// use autoshovel_optim::{Evaluation, FnProblem, Problem};
///
/// // min x² + y² subject to x + y ≥ 1, i.e. g(x) = 1 − x − y ≤ 0.
/// let p = FnProblem::new(vec![(-2.0, 2.0); 2], |x: &[f64]| {
///     Evaluation::new(x[0] * x[0] + x[1] * x[1], (1.0 - x[0] - x[1]).max(0.0))
/// });
/// assert_eq!(p.bounds().len(), 2);
/// assert!(p.evaluate(&[0.5, 0.5]).is_feasible());
/// ```
#[derive(Clone, Debug)]
pub struct FnProblem<F> {
    bounds: Vec<(f64, f64)>,
    f: F,
}

impl<F> FnProblem<F>
where
    F: Fn(&[f64]) -> Evaluation + Sync,
{
    /// Wraps `f` with the box `bounds` (checked by [`crate::minimize`]).
    pub fn new(bounds: Vec<(f64, f64)>, f: F) -> Self {
        Self { bounds, f }
    }
}

impl<F> Problem for FnProblem<F>
where
    F: Fn(&[f64]) -> Evaluation + Sync,
{
    fn bounds(&self) -> &[(f64, f64)] {
        &self.bounds
    }

    fn evaluate(&self, x: &[f64]) -> Evaluation {
        (self.f)(x)
    }
}

/// Every bound pair finite with lower < upper, and at least one.
pub(crate) fn check_bounds(bounds: &[(f64, f64)]) -> Result<(), OptimError> {
    if bounds.is_empty() {
        return Err(OptimError::EmptyBounds);
    }
    for (dim, &(lower, upper)) in bounds.iter().enumerate() {
        if !(lower.is_finite() && upper.is_finite() && lower < upper) {
            return Err(OptimError::BadBounds { dim, lower, upper });
        }
    }
    Ok(())
}

/// A starting point (warm-start wolf `wolf`) of the problem's dimension,
/// every coordinate finite.
pub(crate) fn check_start(wolf: usize, x: &[f64], dims: usize) -> Result<(), OptimError> {
    if x.len() != dims {
        return Err(OptimError::WarmStartDimension {
            wolf,
            expected: dims,
            got: x.len(),
        });
    }
    if let Some((dim, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(OptimError::WarmStartNotFinite { wolf, dim, value });
    }
    Ok(())
}

impl Evaluation {
    /// A value the optimisers can rank: the objective not NaN, the violation
    /// not NaN nor negative; `x` names the point in the error.
    pub(crate) fn check(
        &self,
        iteration: usize,
        wolf: usize,
        x: impl FnOnce() -> Vec<f64>,
    ) -> Result<(), OptimError> {
        if self.objective.is_nan() {
            return Err(OptimError::NanObjective {
                iteration,
                wolf,
                x: x(),
            });
        }
        if self.violation.is_nan() || self.violation < 0.0 {
            return Err(OptimError::BadViolation {
                iteration,
                wolf,
                violation: self.violation,
                x: x(),
            });
        }
        Ok(())
    }
}
