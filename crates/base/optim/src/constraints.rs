//! How two evaluations are ranked, which is all the optimiser needs to pick
//! its leaders α, β, δ: Deb's feasibility rules (Deb 2000, "An efficient
//! constraint handling method for genetic algorithms", Comput. Methods
//! Appl. Mech. Eng. 186:311–338) or a static penalty.

use std::cmp::Ordering;

use serde::{Deserialize, Serialize};

use crate::problem::Evaluation;

/// Constraint handling: how an objective and a violation are compared.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub enum Constraints {
    /// Deb's rules: a feasible point (violation 0) beats any infeasible one;
    /// two infeasible points compare by violation (then objective); two
    /// feasible points by objective. Needs no tuning.
    #[default]
    FeasibilityRules,
    /// Static penalty: objective + weight · violation, compared as one
    /// number (the violation term is skipped when it is 0, so a weight of 0
    /// never meets an infinite violation as 0 · ∞).
    Penalty {
        /// Weight of the violation, finite and ≥ 0.
        weight: f64,
    },
}

impl Constraints {
    /// The rule's name as summaries print it: `feasibility rules (Deb 2000)`
    /// or `static penalty`.
    pub fn name(&self) -> &'static str {
        match self {
            Constraints::FeasibilityRules => "feasibility rules (Deb 2000)",
            Constraints::Penalty { .. } => "static penalty",
        }
    }

    /// Compares `a` with `b`: `Less` when `a` is better. NaN never reaches
    /// here ([`crate::minimize`] rejects it); infinities order as usual.
    pub fn compare(&self, a: &Evaluation, b: &Evaluation) -> Ordering {
        match *self {
            Constraints::FeasibilityRules => match (a.violation > 0.0, b.violation > 0.0) {
                (false, false) => a.objective.total_cmp(&b.objective),
                (false, true) => Ordering::Less,
                (true, false) => Ordering::Greater,
                (true, true) => a
                    .violation
                    .total_cmp(&b.violation)
                    .then(a.objective.total_cmp(&b.objective)),
            },
            Constraints::Penalty { weight } => {
                penalized(a, weight).total_cmp(&penalized(b, weight))
            }
        }
    }
}

/// objective + weight · violation, without 0 · ∞ = NaN.
fn penalized(e: &Evaluation, weight: f64) -> f64 {
    if e.violation > 0.0 && weight > 0.0 {
        e.objective + weight * e.violation
    } else {
        e.objective
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deb_rules() {
        let c = Constraints::FeasibilityRules;
        let feasible_bad = Evaluation::feasible(100.0);
        let infeasible_good = Evaluation::new(-100.0, 1e-9);
        let infeasible_worse = Evaluation::new(-200.0, 1.0);
        assert_eq!(c.compare(&feasible_bad, &infeasible_good), Ordering::Less);
        assert_eq!(
            c.compare(&infeasible_good, &infeasible_worse),
            Ordering::Less
        );
        assert_eq!(
            c.compare(&Evaluation::feasible(1.0), &Evaluation::feasible(2.0)),
            Ordering::Less
        );
    }

    #[test]
    fn penalty_is_one_number() {
        let c = Constraints::Penalty { weight: 10.0 };
        // 1 + 10 · 0.05 = 1.5 < 2 (feasible): the infeasible point wins.
        assert_eq!(
            c.compare(&Evaluation::new(1.0, 0.05), &Evaluation::feasible(2.0)),
            Ordering::Less
        );
        let zero = Constraints::Penalty { weight: 0.0 };
        assert_eq!(
            zero.compare(
                &Evaluation::new(1.0, f64::INFINITY),
                &Evaluation::feasible(2.0)
            ),
            Ordering::Less
        );
    }
}
