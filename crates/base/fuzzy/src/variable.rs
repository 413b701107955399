//! Linguistic variables: a named universe of discourse `[min, max]` and its
//! named terms, and the fuzzification of a crisp value into one degree per
//! term (Mamdani & Assilian 1975). The paper's §4.3 uses three of them:
//! e ∈ [−0.45, 0.45] (m), ec ∈ [−30, 30] and u ∈ [−2700, 2700] (rpm), each
//! with seven evenly spaced triangles NB … PB.
//!
//! Crisp inputs are clamped to the universe before fuzzification, so values
//! beyond an edge count as the edge itself: with shoulder end terms, NB / PB
//! saturate at degree 1 as a controller expects.

use serde::{Deserialize, Serialize};

use crate::{FuzzyError, Membership};

/// A linguistic variable: a name, a universe `[min, max]` and ordered,
/// uniquely named terms.
///
/// A plain struct: build it by hand or with the helpers, then let
/// [`Variable::check`] (called by every system constructor) validate it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Variable {
    /// Name, used in error messages and traces (e.g. `"e"`).
    pub name: String,
    /// Lower end of the universe of discourse.
    pub min: f64,
    /// Upper end of the universe of discourse.
    pub max: f64,
    /// Terms in order: name and membership function.
    pub terms: Vec<(String, Membership)>,
}

impl Variable {
    /// A variable with a universe and no terms yet (add them with
    /// [`Variable::with_term`]).
    pub fn new(name: impl Into<String>, min: f64, max: f64) -> Self {
        Variable {
            name: name.into(),
            min,
            max,
            terms: Vec::new(),
        }
    }

    /// Appends a term (builder style). Checked later by [`Variable::check`].
    pub fn with_term(mut self, name: impl Into<String>, membership: Membership) -> Self {
        self.terms.push((name.into(), membership));
        self
    }

    /// A partition of `[min, max]` into `names.len()` evenly spaced
    /// triangles, the usual drawing of a controller's term set (the paper's
    /// Fig. 8 for e, ec and u).
    ///
    /// The peaks are the points `cᵢ` of [`Variable::sample`] (exactly
    /// mirror-symmetric on a symmetric universe, so ZE peaks at exactly 0
    /// and the partition is exactly odd); term i is the triangle
    /// `(cᵢ₋₁, cᵢ, cᵢ₊₁)`, so neighbours cross at degree ½ and the degrees
    /// sum to 1 everywhere. The first and last terms are *shoulders* at the
    /// universe edges, `(c₀, c₀, c₁)` and `(cₙ₋₂, cₙ₋₁, cₙ₋₁)`: degree 1 at
    /// and beyond the edge.
    ///
    /// Comparison with scikit-fuzzy 0.5's `FuzzyVariable.automf(n, names=…)`:
    /// automf centres the same peaks but draws every term, the end ones too,
    /// as a full triangle `cᵢ ± (max − min)/(n − 1)`, so its NB and PB are
    /// triangles whose outer half lies outside the universe. Inside the
    /// universe the two partitions have the same values (up to the rounding
    /// of the feet, which automf computes as `cᵢ ± w/2` rather than taking
    /// the neighbouring peak), and scikit-fuzzy only ever samples the
    /// universe and clips inputs to it (`clip_to_bounds=True`), so the two
    /// infer the same outputs. They differ only when a membership function is
    /// evaluated outside the universe without clipping: automf's end terms
    /// fall to 0 one step beyond the edge, ours stay at 1. (Checked by
    /// `peer/skfuzzy_table1.py`, which prints the largest difference.)
    ///
    /// Errors: fewer than two names ([`FuzzyError::TooFewTerms`]), a bad
    /// universe or duplicate names (see [`Variable::check`]).
    pub fn evenly_spaced_triangles(
        name: impl Into<String>,
        min: f64,
        max: f64,
        names: &[&str],
    ) -> Result<Self, FuzzyError> {
        let name = name.into();
        let n = names.len();
        if n < 2 {
            return Err(FuzzyError::TooFewTerms {
                variable: name,
                needed: 2,
                got: n,
            });
        }
        let mut var = Variable::new(name, min, max);
        let peak = |i: usize| var_sample(min, max, n, i);
        for (i, term) in names.iter().enumerate() {
            let b = peak(i);
            let a = if i == 0 { b } else { peak(i - 1) };
            let c = if i + 1 == n { b } else { peak(i + 1) };
            var.terms
                .push(((*term).to_string(), Membership::Triangle { a, b, c }));
        }
        var.check()?;
        Ok(var)
    }

    /// Validates the variable: finite universe with `min < max`, at least one
    /// term, unique term names, every membership function valid
    /// ([`Membership::check`]) and reaching a positive degree somewhere in
    /// the universe.
    pub fn check(&self) -> Result<(), FuzzyError> {
        if !(self.min.is_finite() && self.max.is_finite() && self.min < self.max) {
            return Err(FuzzyError::EmptyUniverse {
                variable: self.name.clone(),
                min: self.min,
                max: self.max,
            });
        }
        if self.terms.is_empty() {
            return Err(FuzzyError::TooFewTerms {
                variable: self.name.clone(),
                needed: 1,
                got: 0,
            });
        }
        for (i, (term, mf)) in self.terms.iter().enumerate() {
            if self.terms[..i].iter().any(|(other, _)| other == term) {
                return Err(FuzzyError::DuplicateTerm {
                    variable: self.name.clone(),
                    term: term.clone(),
                });
            }
            let bad = |why| FuzzyError::BadMembership {
                variable: self.name.clone(),
                term: term.clone(),
                why,
            };
            mf.check().map_err(bad)?;
            let (lo, hi) = mf.core();
            if mf.degree(self.clamp(0.5 * (lo + hi))) <= 0.0 {
                return Err(bad("membership is 0 everywhere inside the universe"));
            }
        }
        Ok(())
    }

    /// Index of the term called `name`, if any.
    pub fn term_index(&self, name: &str) -> Option<usize> {
        self.terms.iter().position(|(t, _)| t == name)
    }

    /// Index of the term called `name`, or [`FuzzyError::UnknownTerm`].
    pub fn require_term(&self, name: &str) -> Result<usize, FuzzyError> {
        self.term_index(name)
            .ok_or_else(|| FuzzyError::UnknownTerm {
                variable: self.name.clone(),
                term: name.to_string(),
            })
    }

    /// `x` clamped to `[min, max]` (NaN stays NaN).
    pub fn clamp(&self, x: f64) -> f64 {
        if x < self.min {
            self.min
        } else if x > self.max {
            self.max
        } else {
            x
        }
    }

    /// Centre of the universe, `(min + max) / 2`.
    pub fn centre(&self) -> f64 {
        0.5 * (self.min + self.max)
    }

    /// Point `i` of `n` evenly spaced points spanning the universe, ends
    /// included: `(min·(n − 1 − i) + max·i) / (n − 1)`, with the ends set to
    /// `min` and `max` exactly. Written this way (rather than
    /// `min + i·step`, `numpy.linspace`'s form, which puts the middle of
    /// [−0.45, 0.45] at −5.6e−17) the points of a symmetric universe are
    /// exact mirror images and its centre is exactly 0. `n < 2` gives `min`.
    pub fn sample(&self, i: usize, n: usize) -> f64 {
        var_sample(self.min, self.max, n, i)
    }

    /// Degree of term `term` at `x` after clamping `x` to the universe;
    /// 0 for an index past the end.
    pub fn degree(&self, term: usize, x: f64) -> f64 {
        self.terms
            .get(term)
            .map_or(0.0, |(_, mf)| mf.degree(self.clamp(x)))
    }

    /// Degrees of all terms at `x` (clamped to the universe), in term order.
    pub fn fuzzify(&self, x: f64) -> Vec<f64> {
        let mut out = vec![0.0; self.terms.len()];
        self.fuzzify_into(x, &mut out);
        out
    }

    /// Writes the degrees of the terms at `x` (clamped to the universe) into
    /// `out`, as many as both lengths allow. Allocation-free.
    pub fn fuzzify_into(&self, x: f64, out: &mut [f64]) {
        let x = self.clamp(x);
        for (o, (_, mf)) in out.iter_mut().zip(&self.terms) {
            *o = mf.degree(x);
        }
    }
}

/// Point `i` of `n` evenly spaced points of `[min, max]`, see
/// [`Variable::sample`].
pub(crate) fn var_sample(min: f64, max: f64, n: usize, i: usize) -> f64 {
    if n < 2 || i == 0 {
        return min;
    }
    if i + 1 >= n {
        return max;
    }
    let (j, n1) = ((n - 1 - i) as f64, (n - 1) as f64);
    (min * j + max * i as f64) / n1
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: [&str; 7] = ["NB", "NM", "NS", "ZE", "PS", "PM", "PB"];

    #[test]
    fn partition_shape() {
        let v = Variable::evenly_spaced_triangles("e", -0.45, 0.45, &NAMES).unwrap();
        assert_eq!(v.terms.len(), 7);
        assert_eq!(
            v.terms[0].1,
            Membership::Triangle {
                a: -0.45,
                b: -0.45,
                c: v.sample(1, 7)
            }
        );
        assert_eq!(v.term_index("ZE"), Some(3));
        assert_eq!(v.term_index("XX"), None);
        // Degrees sum to 1 and the ends saturate beyond the universe.
        for k in 0..=90 {
            let x = -0.5 + k as f64 * 0.011;
            let s: f64 = v.fuzzify(x).iter().sum();
            assert!((s - 1.0).abs() < 1e-12, "sum {s} at {x}");
        }
        assert_eq!(v.degree(0, -7.0), 1.0);
        assert_eq!(v.degree(6, 7.0), 1.0);
        assert_eq!(v.degree(3, 0.0), 1.0);
        assert_eq!(v.degree(99, 0.0), 0.0);
    }

    #[test]
    fn checks() {
        assert!(matches!(
            Variable::evenly_spaced_triangles("e", 1.0, 1.0, &NAMES),
            Err(FuzzyError::EmptyUniverse { .. })
        ));
        assert!(matches!(
            Variable::evenly_spaced_triangles("e", 0.0, 1.0, &["A"]),
            Err(FuzzyError::TooFewTerms { got: 1, .. })
        ));
        assert!(matches!(
            Variable::evenly_spaced_triangles("e", 0.0, 1.0, &["A", "A"]),
            Err(FuzzyError::DuplicateTerm { .. })
        ));
        let outside = Variable::new("x", 0.0, 1.0).with_term(
            "far",
            Membership::Triangle {
                a: 2.0,
                b: 3.0,
                c: 4.0,
            },
        );
        assert!(matches!(
            outside.check(),
            Err(FuzzyError::BadMembership { ref term, .. }) if term == "far"
        ));
        assert!(matches!(
            Variable::new("x", 0.0, 1.0).require_term("A"),
            Err(FuzzyError::UnknownTerm { .. })
        ));
    }

    #[test]
    fn samples_are_symmetric() {
        let v = Variable::new("u", -2700.0, 2700.0);
        assert_eq!(v.sample(0, 201), -2700.0);
        assert_eq!(v.sample(100, 201), 0.0);
        assert_eq!(v.sample(101, 201), 27.0);
        assert_eq!(v.sample(200, 201), 2700.0);
        let e = Variable::new("e", -0.45, 0.45);
        for n in [2, 7, 21, 200, 201] {
            for i in 0..n {
                assert_eq!(e.sample(i, n), -e.sample(n - 1 - i, n), "{i} of {n}");
            }
        }
        assert_eq!(e.sample(3, 7), 0.0);
        assert_eq!(e.sample(1, 1), -0.45);
    }
}
