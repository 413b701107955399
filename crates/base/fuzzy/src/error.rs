//! The one error type of the crate: everything that can be wrong with a
//! membership function, a linguistic variable, a rule base or an inference
//! call, each variant naming the value at fault.
//!
//! Definitions are checked once, when a [`crate::MamdaniSystem`] is built
//! (Mamdani & Assilian 1975 leave validity to the designer; a controller such
//! as the crawler tracker of the paper's §4.3 must not find out at run time).
//! After that, inference can only fail on its arguments (count, finiteness).

use thiserror::Error;

/// Everything that can go wrong building or evaluating a fuzzy system.
#[non_exhaustive]
#[derive(Debug, Clone, PartialEq, Error)]
pub enum FuzzyError {
    /// A variable's universe `[min, max]` is empty, reversed or not finite.
    #[error("variable `{variable}`: universe [{min}, {max}] is empty or not finite")]
    EmptyUniverse {
        /// Name of the variable.
        variable: String,
        /// Lower end of the universe as given.
        min: f64,
        /// Upper end of the universe as given.
        max: f64,
    },
    /// A variable has no terms, or fewer than a helper needs.
    #[error("variable `{variable}`: needs at least {needed} term(s), got {got}")]
    TooFewTerms {
        /// Name of the variable.
        variable: String,
        /// Least number of terms accepted.
        needed: usize,
        /// Number of terms given.
        got: usize,
    },
    /// Two terms of one variable share a name.
    #[error("variable `{variable}`: term `{term}` is defined twice")]
    DuplicateTerm {
        /// Name of the variable.
        variable: String,
        /// The repeated term name.
        term: String,
    },
    /// A membership function's parameters are invalid.
    #[error("variable `{variable}`, term `{term}`: bad membership function: {why}")]
    BadMembership {
        /// Name of the variable holding the term.
        variable: String,
        /// Name of the term.
        term: String,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A term name looked up (in a rule or table) does not exist.
    #[error("variable `{variable}` has no term `{term}`")]
    UnknownTerm {
        /// Name of the variable searched.
        variable: String,
        /// The name that was not found.
        term: String,
    },
    /// A rule refers to a term index past the end of a variable's terms.
    #[error("rule {rule}: term index {index} out of range for `{variable}` ({count} terms)")]
    TermIndex {
        /// Index of the rule in the rule list.
        rule: usize,
        /// Name of the variable indexed.
        variable: String,
        /// The offending index.
        index: usize,
        /// Number of terms the variable has.
        count: usize,
    },
    /// A rule's antecedent does not name one term per input.
    #[error("rule {rule}: antecedent has {got} term(s), the system has {expected} input(s)")]
    RuleArity {
        /// Index of the rule in the rule list.
        rule: usize,
        /// Number of inputs of the system.
        expected: usize,
        /// Length of the rule's antecedent.
        got: usize,
    },
    /// A rule weight outside `[0, 1]` or not finite.
    #[error("rule {rule}: weight {weight} is not in [0, 1]")]
    BadWeight {
        /// Index of the rule in the rule list.
        rule: usize,
        /// The offending weight.
        weight: f64,
    },
    /// A system with no inputs.
    #[error("a fuzzy system needs at least one input variable")]
    NoInputs,
    /// A system with no rules.
    #[error("a fuzzy system needs at least one rule")]
    NoRules,
    /// Fewer than two output samples requested.
    #[error("output resolution {resolution} is below 2 samples")]
    BadResolution {
        /// The requested number of samples.
        resolution: usize,
    },
    /// A rule table has the wrong number of rows.
    #[error("rule table has {got} row(s), the row variable `{variable}` has {expected} term(s)")]
    TableRows {
        /// Name of the row variable.
        variable: String,
        /// Number of terms of the row variable.
        expected: usize,
        /// Number of rows given.
        got: usize,
    },
    /// A rule-table row has the wrong number of cells.
    #[error(
        "rule table row {row} has {got} cell(s), the column variable `{variable}` has {expected} term(s)"
    )]
    TableColumns {
        /// Index of the offending row.
        row: usize,
        /// Name of the column variable.
        variable: String,
        /// Number of terms of the column variable.
        expected: usize,
        /// Number of cells in that row.
        got: usize,
    },
    /// An inference call with the wrong number of inputs.
    #[error("expected {expected} input value(s), got {got}")]
    InputCount {
        /// Number of inputs of the system.
        expected: usize,
        /// Number of values given.
        got: usize,
    },
    /// An input value is NaN or infinite.
    #[error("input `{input}` is not finite: {value}")]
    NotFinite {
        /// Name of the input variable.
        input: String,
        /// The value given.
        value: f64,
    },
    /// A grid with fewer than two points per axis.
    #[error("a surface grid needs at least 2 × 2 points, got {nx} × {ny}")]
    BadGrid {
        /// Points along the first input.
        nx: usize,
        /// Points along the second input.
        ny: usize,
    },
    /// A two-input operation (control surface) on a system with another arity.
    #[error("a control surface needs exactly 2 inputs, the system has {inputs}")]
    NotTwoInputs {
        /// Number of inputs of the system.
        inputs: usize,
    },
}
