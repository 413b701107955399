//! Rule bases: "IF x₁ is A₁ AND … AND xₙ is Aₙ THEN y is B (weight w)",
//! stored as term indices (Mamdani & Assilian 1975). Helpers build them
//! from term names, or from the two-input table a controller designer draws
//! (the paper's §4.3 Table 1: rows ec, columns e, cells u).
//!
//! Nothing here knows a particular table: the crawler-tracking table is a
//! test fixture of this crate and belongs to the tracking crate.

use serde::{Deserialize, Serialize};

use crate::{FuzzyError, Variable};

/// One rule: a term index per input (AND-ed), the output term, a weight.
///
/// Firing strength = `weight × minᵢ μ(input i is term antecedent[i])`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rule {
    /// Term index for each input, in the system's input order.
    pub antecedent: Vec<usize>,
    /// Term index of the output variable.
    pub consequent: usize,
    /// Weight in `[0, 1]` scaling the firing strength (1 by default).
    pub weight: f64,
}

impl Rule {
    /// A rule of weight 1.
    pub fn new(antecedent: Vec<usize>, consequent: usize) -> Self {
        Rule {
            antecedent,
            consequent,
            weight: 1.0,
        }
    }
}

/// An ordered list of rules, with builders working on term names.
///
/// Indices are checked against the variables when a
/// [`crate::MamdaniSystem`] is built; the name-based helpers check names as
/// they go.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RuleBase {
    /// The rules, in evaluation (and trace) order.
    pub rules: Vec<Rule>,
}

impl RuleBase {
    /// An empty rule base.
    pub fn new() -> Self {
        RuleBase::default()
    }

    /// Appends a rule given by indices.
    pub fn push(&mut self, rule: Rule) -> &mut Self {
        self.rules.push(rule);
        self
    }

    /// Appends "IF inputs\[0\] is antecedent\[0\] AND … THEN output is
    /// consequent" with weight `weight`, looking the names up.
    ///
    /// Errors: [`FuzzyError::RuleArity`] if `antecedent` does not name one
    /// term per input, [`FuzzyError::UnknownTerm`] for a name that is not a
    /// term of its variable, [`FuzzyError::BadWeight`] outside `[0, 1]`.
    pub fn add(
        &mut self,
        inputs: &[Variable],
        output: &Variable,
        antecedent: &[&str],
        consequent: &str,
        weight: f64,
    ) -> Result<&mut Self, FuzzyError> {
        let rule = self.rules.len();
        if antecedent.len() != inputs.len() {
            return Err(FuzzyError::RuleArity {
                rule,
                expected: inputs.len(),
                got: antecedent.len(),
            });
        }
        if !(0.0..=1.0).contains(&weight) {
            return Err(FuzzyError::BadWeight { rule, weight });
        }
        let antecedent = inputs
            .iter()
            .zip(antecedent)
            .map(|(var, term)| var.require_term(term))
            .collect::<Result<Vec<_>, _>>()?;
        let consequent = output.require_term(consequent)?;
        self.rules.push(Rule {
            antecedent,
            consequent,
            weight,
        });
        Ok(self)
    }

    /// The complete rule base of a two-input table, one weight-1 rule per
    /// cell.
    ///
    /// Orientation: **columns are the first input, rows the second**.
    /// `table[r][c]` names the output term of the rule
    /// "IF input₀ (`columns`) is `columns.terms[c]` AND input₁ (`rows`) is
    /// `rows.terms[r]`", and the rule's antecedent is `[c, r]` — so the
    /// system must be built with inputs `[columns, rows]`. For the paper's
    /// Table 1, `columns` is e, `rows` is ec. Rules are emitted row by row.
    ///
    /// Errors: [`FuzzyError::TableRows`] / [`FuzzyError::TableColumns`] if
    /// the table is not `rows.terms.len() × columns.terms.len()`,
    /// [`FuzzyError::UnknownTerm`] (naming the output variable) for a cell
    /// that is not an output term.
    pub fn from_table(
        columns: &Variable,
        rows: &Variable,
        output: &Variable,
        table: &[&[&str]],
    ) -> Result<Self, FuzzyError> {
        if table.len() != rows.terms.len() {
            return Err(FuzzyError::TableRows {
                variable: rows.name.clone(),
                expected: rows.terms.len(),
                got: table.len(),
            });
        }
        let mut base = RuleBase::new();
        for (r, row) in table.iter().enumerate() {
            if row.len() != columns.terms.len() {
                return Err(FuzzyError::TableColumns {
                    row: r,
                    variable: columns.name.clone(),
                    expected: columns.terms.len(),
                    got: row.len(),
                });
            }
            for (c, cell) in row.iter().enumerate() {
                let consequent = output.require_term(cell)?;
                base.rules.push(Rule::new(vec![c, r], consequent));
            }
        }
        Ok(base)
    }

    /// Number of rules.
    pub fn len(&self) -> usize {
        self.rules.len()
    }

    /// Whether there are no rules.
    pub fn is_empty(&self) -> bool {
        self.rules.is_empty()
    }
}

impl From<RuleBase> for Vec<Rule> {
    fn from(base: RuleBase) -> Self {
        base.rules
    }
}

impl From<Vec<Rule>> for RuleBase {
    fn from(rules: Vec<Rule>) -> Self {
        RuleBase { rules }
    }
}
