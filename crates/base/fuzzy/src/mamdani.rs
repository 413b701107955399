//! Mamdani inference (Mamdani & Assilian 1975): fuzzify every input, fire
//! every rule with min for AND (times its weight), clip each output term at
//! the largest strength of the rules concluding it (min implication), take
//! the max over terms (max aggregation) and return the centroid of that
//! aggregated set. The paper's §4.3 crawler tracking controller is this with
//! inputs e, ec, output u and the 7 × 7 Table 1.
//!
//! # Discretisation
//! The output universe is sampled at `resolution` evenly spaced points
//! ([`Variable::sample`], default [`DEFAULT_RESOLUTION`] = 201), and
//! each output term is represented by its samples, linear in between. The
//! aggregated set is evaluated at those samples *and* at every point where
//! a term's (interpolated) membership crosses its clipping level — the
//! corners of the clipped shapes — and the centroid is the exact centroid of
//! the piecewise-linear curve through all these points. This is precisely
//! what scikit-fuzzy 0.5's `ControlSystemSimulation` computes (its
//! `find_memberships` + `defuzz(…, 'centroid')`), so the two agree to
//! rounding (tests/peer_skfuzzy.rs). What remains approximate: an output
//! term's peak or foot that falls between two samples is cut by the chord,
//! and where two clipped terms cross between samples the crossing is not
//! inserted either. For the 7-term ±2700 rpm partition at 201 samples this
//! moves u by at most ≈ 0.34 rpm from the continuous centroid (measured
//! against [`MamdaniSystem::infer_dense`] by the tests); a resolution that
//! puts every term breakpoint on a sample (181 or 241 there) removes the
//! first effect.
//!
//! # Hot path
//! Construction samples the output terms once (a `resolution × terms`
//! table). An inference then costs one membership evaluation per input
//! term, one min per antecedent and rule, and one pass over the samples
//! spanned by the terms that fired, touching only those terms; segments
//! without a clipping corner are summed in closed form. No allocation
//! ([`MamdaniSystem::infer`] keeps its buffers on the stack for up to 64
//! terms per side, [`MamdaniSystem::infer_with`] reuses a [`Scratch`]).
//! About 0.2–0.6 µs for the 7 × 7 table on the project's machine
//! (benches/infer.rs).

use serde::{Deserialize, Serialize};

use crate::variable::var_sample;
use crate::{FuzzyError, Rule, Variable};

/// Default number of output samples.
pub const DEFAULT_RESOLUTION: usize = 201;

/// Term counts up to which [`MamdaniSystem::infer`] needs no heap buffers.
const STACK_TERMS: usize = 64;

/// A validated Mamdani fuzzy system with its precomputed output sampling.
///
/// Built only through [`MamdaniSystem::new`] / [`MamdaniSystem::with_resolution`],
/// which check everything; afterwards inference fails only on its arguments.
#[derive(Debug, Clone)]
pub struct MamdaniSystem {
    inputs: Vec<Variable>,
    output: Variable,
    rules: Vec<Rule>,
    resolution: usize,
    /// `offsets[i]`: position of input i's first term in the flat degree
    /// buffer; `offsets[inputs.len()]` is the total number of input terms.
    offsets: Vec<usize>,
    /// `flat[r * inputs.len() + i]`: flat degree index of rule r's term on
    /// input i.
    flat: Vec<usize>,
    /// Output samples (the `resolution` grid).
    grid: Vec<f64>,
    /// Grid step `(max − min) / (resolution − 1)`.
    step: f64,
    /// Sampled output terms, sample-major: `sampled[k * n_terms + t]` is
    /// term t's degree at `grid[k]`.
    sampled: Vec<f64>,
    /// Per output term, the sample range `[first, last]` outside which the
    /// term is zero on every segment (its positive samples plus one each
    /// side).
    support: Vec<(usize, usize)>,
}

/// Reusable buffers for [`MamdaniSystem::infer_with`].
///
/// Get one sized for a system from [`MamdaniSystem::scratch`]; a scratch of
/// the wrong size (e.g. `Scratch::default()`, or one from another system)
/// is resized on first use, after which that system's inferences do not
/// allocate.
#[derive(Debug, Clone, Default)]
pub struct Scratch {
    degrees: Vec<f64>,
    strengths: Vec<f64>,
    fired: Vec<usize>,
}

impl Scratch {
    fn fit(&mut self, degrees: usize, terms: usize) {
        if self.degrees.len() != degrees {
            self.degrees.resize(degrees, 0.0);
        }
        if self.strengths.len() != terms {
            self.strengths.resize(terms, 0.0);
            self.fired.resize(terms, 0);
        }
    }
}

/// Everything an inference computed, for debugging and plots.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trace {
    /// The crisp output (what [`MamdaniSystem::infer`] returns).
    pub output: f64,
    /// The inputs after clamping to their universes.
    pub inputs: Vec<f64>,
    /// `degrees[i][t]`: degree of input i's term t.
    pub degrees: Vec<Vec<f64>>,
    /// `(rule index, firing strength)` of every rule with strength > 0, in
    /// rule order (strength includes the rule weight).
    pub fired: Vec<(usize, f64)>,
    /// Clipping level of every output term (max strength of its rules).
    pub term_strengths: Vec<f64>,
    /// True when no rule fired (or the fired terms had no area), so
    /// `output` is the fallback: the centre of the output universe.
    pub fallback: bool,
}

impl MamdaniSystem {
    /// A system with the default output resolution ([`DEFAULT_RESOLUTION`]).
    /// See [`MamdaniSystem::with_resolution`].
    pub fn new(
        inputs: Vec<Variable>,
        output: Variable,
        rules: impl Into<Vec<Rule>>,
    ) -> Result<Self, FuzzyError> {
        Self::with_resolution(inputs, output, rules, DEFAULT_RESOLUTION)
    }

    /// Validates and builds a system whose output universe is sampled at
    /// `resolution` points.
    ///
    /// Checks: at least one input ([`FuzzyError::NoInputs`]); every
    /// variable ([`Variable::check`]); at least one rule
    /// ([`FuzzyError::NoRules`]); every rule has one term per input
    /// ([`FuzzyError::RuleArity`]), indices in range
    /// ([`FuzzyError::TermIndex`]) and a weight in `[0, 1]`
    /// ([`FuzzyError::BadWeight`]); `resolution ≥ 2`
    /// ([`FuzzyError::BadResolution`]); every output term is positive at
    /// some output sample ([`FuzzyError::BadMembership`] otherwise: a term
    /// narrower than the sampling step would be invisible).
    pub fn with_resolution(
        inputs: Vec<Variable>,
        output: Variable,
        rules: impl Into<Vec<Rule>>,
        resolution: usize,
    ) -> Result<Self, FuzzyError> {
        let rules = rules.into();
        if inputs.is_empty() {
            return Err(FuzzyError::NoInputs);
        }
        for var in &inputs {
            var.check()?;
        }
        output.check()?;
        if rules.is_empty() {
            return Err(FuzzyError::NoRules);
        }
        for (r, rule) in rules.iter().enumerate() {
            if rule.antecedent.len() != inputs.len() {
                return Err(FuzzyError::RuleArity {
                    rule: r,
                    expected: inputs.len(),
                    got: rule.antecedent.len(),
                });
            }
            let indexed = rule
                .antecedent
                .iter()
                .zip(&inputs)
                .chain(std::iter::once((&rule.consequent, &output)));
            for (&index, var) in indexed {
                if index >= var.terms.len() {
                    return Err(FuzzyError::TermIndex {
                        rule: r,
                        variable: var.name.clone(),
                        index,
                        count: var.terms.len(),
                    });
                }
            }
            if !(0.0..=1.0).contains(&rule.weight) {
                return Err(FuzzyError::BadWeight {
                    rule: r,
                    weight: rule.weight,
                });
            }
        }
        if resolution < 2 {
            return Err(FuzzyError::BadResolution { resolution });
        }

        let mut offsets = Vec::with_capacity(inputs.len() + 1);
        let mut total = 0;
        for var in &inputs {
            offsets.push(total);
            total += var.terms.len();
        }
        offsets.push(total);
        let flat = rules
            .iter()
            .flat_map(|rule| rule.antecedent.iter().zip(&offsets).map(|(t, o)| o + t))
            .collect();

        let grid: Vec<f64> = (0..resolution)
            .map(|k| output.sample(k, resolution))
            .collect();
        let sampled: Vec<f64> = grid
            .iter()
            .flat_map(|&y| output.terms.iter().map(move |(_, mf)| mf.degree(y)))
            .collect();
        let n_terms = output.terms.len();
        let mut support = Vec::with_capacity(n_terms);
        for (t, (term, _)) in output.terms.iter().enumerate() {
            let positive = |k: &usize| sampled[k * n_terms + t] > 0.0;
            let (Some(first), Some(last)) = (
                (0..resolution).find(positive),
                (0..resolution).rev().find(positive),
            ) else {
                return Err(FuzzyError::BadMembership {
                    variable: output.name.clone(),
                    term: term.clone(),
                    why: "no output sample has a positive degree; raise the resolution",
                });
            };
            support.push((first.saturating_sub(1), (last + 1).min(resolution - 1)));
        }
        let step = (output.max - output.min) / (resolution - 1) as f64;

        Ok(MamdaniSystem {
            inputs,
            output,
            rules,
            resolution,
            offsets,
            flat,
            grid,
            step,
            sampled,
            support,
        })
    }

    /// The input variables, in the order inference expects their values.
    pub fn inputs(&self) -> &[Variable] {
        &self.inputs
    }

    /// The output variable.
    pub fn output(&self) -> &Variable {
        &self.output
    }

    /// The rules, in evaluation order.
    pub fn rules(&self) -> &[Rule] {
        &self.rules
    }

    /// Number of output samples.
    pub fn resolution(&self) -> usize {
        self.resolution
    }

    /// The output samples (`resolution` evenly spaced points of the output
    /// universe, ends included).
    pub fn output_samples(&self) -> &[f64] {
        &self.grid
    }

    /// Buffers sized for [`MamdaniSystem::infer_with`].
    pub fn scratch(&self) -> Scratch {
        let mut s = Scratch::default();
        s.fit(self.offsets[self.inputs.len()], self.output.terms.len());
        s
    }

    /// The crisp output for inputs `x` (one value per input, in order).
    ///
    /// Inputs outside a universe are clamped to its edge. When no rule
    /// fires, the result is the centre of the output universe (a controller
    /// must always command something); [`MamdaniSystem::infer_traced`] says
    /// when that happened. The result always lies in the output universe.
    ///
    /// Errors: [`FuzzyError::InputCount`], [`FuzzyError::NotFinite`]. No
    /// allocation for up to 64 input terms in total and 64 output terms
    /// (beyond that it allocates a [`Scratch`]; use
    /// [`MamdaniSystem::infer_with`]).
    pub fn infer(&self, x: &[f64]) -> Result<f64, FuzzyError> {
        self.check_inputs(x)?;
        let n_in = self.offsets[self.inputs.len()];
        let n_out = self.output.terms.len();
        if n_in <= STACK_TERMS && n_out <= STACK_TERMS {
            let mut degrees = [0.0; STACK_TERMS];
            let mut strengths = [0.0; STACK_TERMS];
            let mut fired = [0; STACK_TERMS];
            Ok(self.run(
                x,
                &mut degrees[..n_in],
                &mut strengths[..n_out],
                &mut fired[..n_out],
            ))
        } else {
            self.infer_with(x, &mut self.scratch())
        }
    }

    /// [`MamdaniSystem::infer`] with caller-owned buffers: never allocates
    /// once `scratch` fits this system (see [`Scratch`]).
    pub fn infer_with(&self, x: &[f64], scratch: &mut Scratch) -> Result<f64, FuzzyError> {
        self.check_inputs(x)?;
        scratch.fit(self.offsets[self.inputs.len()], self.output.terms.len());
        Ok(self.run(
            x,
            &mut scratch.degrees,
            &mut scratch.strengths,
            &mut scratch.fired,
        ))
    }

    /// [`MamdaniSystem::infer`] plus every intermediate value (allocates).
    pub fn infer_traced(&self, x: &[f64]) -> Result<Trace, FuzzyError> {
        self.check_inputs(x)?;
        let mut scratch = self.scratch();
        self.fuzzify(x, &mut scratch.degrees);
        self.fire(&scratch.degrees, &mut scratch.strengths);
        let defuzzified = self.centroid(&scratch.strengths, &mut scratch.fired);
        let fired = (0..self.rules.len())
            .map(|r| (r, self.rule_strength(r, &scratch.degrees)))
            .filter(|&(_, s)| s > 0.0)
            .collect();
        let degrees = self
            .offsets
            .windows(2)
            .map(|w| scratch.degrees[w[0]..w[1]].to_vec())
            .collect();
        Ok(Trace {
            output: self.crisp(defuzzified),
            inputs: x
                .iter()
                .zip(&self.inputs)
                .map(|(&v, var)| var.clamp(v))
                .collect(),
            degrees,
            fired,
            term_strengths: scratch.strengths,
            fallback: defuzzified.is_none(),
        })
    }

    /// Reference inference for tests: the same fuzzification and rule
    /// firing, but the aggregated set is built from the *exact* output
    /// membership functions evaluated at `samples` evenly spaced points, and
    /// its piecewise-linear centroid taken. With `samples` = 100 001 this is
    /// the continuous centroid to well below 10⁻³ [output unit] for the
    /// usual partitions, which bounds the discretisation error of
    /// [`MamdaniSystem::infer`]. Cost O(samples × output terms).
    ///
    /// Errors: as [`MamdaniSystem::infer`], plus
    /// [`FuzzyError::BadResolution`] for `samples < 2`.
    pub fn infer_dense(&self, x: &[f64], samples: usize) -> Result<f64, FuzzyError> {
        self.check_inputs(x)?;
        if samples < 2 {
            return Err(FuzzyError::BadResolution {
                resolution: samples,
            });
        }
        let mut scratch = self.scratch();
        self.fuzzify(x, &mut scratch.degrees);
        self.fire(&scratch.degrees, &mut scratch.strengths);
        let strengths = &scratch.strengths;
        let aggregate = |y: f64| {
            self.output
                .terms
                .iter()
                .zip(strengths)
                .fold(0.0f64, |m, ((_, mf), &s)| m.max(s.min(mf.degree(y))))
        };
        let mut acc = Centroid::default();
        let mut y0 = self.output.sample(0, samples);
        let mut m0 = aggregate(y0);
        for k in 1..samples {
            let y1 = self.output.sample(k, samples);
            let m1 = aggregate(y1);
            acc.add(y0, m0, y1, m1);
            (y0, m0) = (y1, m1);
        }
        Ok(self.crisp(acc.value()))
    }

    /// Input count and finiteness.
    fn check_inputs(&self, x: &[f64]) -> Result<(), FuzzyError> {
        if x.len() != self.inputs.len() {
            return Err(FuzzyError::InputCount {
                expected: self.inputs.len(),
                got: x.len(),
            });
        }
        for (&value, var) in x.iter().zip(&self.inputs) {
            if !value.is_finite() {
                return Err(FuzzyError::NotFinite {
                    input: var.name.clone(),
                    value,
                });
            }
        }
        Ok(())
    }

    /// Fuzzify, fire, defuzzify on checked inputs; buffers of exact size.
    fn run(
        &self,
        x: &[f64],
        degrees: &mut [f64],
        strengths: &mut [f64],
        fired: &mut [usize],
    ) -> f64 {
        self.fuzzify(x, degrees);
        self.fire(degrees, strengths);
        self.crisp(self.centroid(strengths, fired))
    }

    /// The centroid clamped into the output universe (guarding against
    /// rounding at the edges), or the universe centre when there is none.
    fn crisp(&self, centroid: Option<f64>) -> f64 {
        centroid.map_or_else(|| self.output.centre(), |c| self.output.clamp(c))
    }

    /// Degrees of all input terms, flattened input by input.
    fn fuzzify(&self, x: &[f64], degrees: &mut [f64]) {
        for ((var, &value), w) in self.inputs.iter().zip(x).zip(self.offsets.windows(2)) {
            var.fuzzify_into(value, &mut degrees[w[0]..w[1]]);
        }
    }

    /// Firing strength of rule `r`: weight × min of its antecedent degrees.
    fn rule_strength(&self, r: usize, degrees: &[f64]) -> f64 {
        let n = self.inputs.len();
        and(&self.flat[r * n..(r + 1) * n], degrees) * self.rules[r].weight
    }

    /// Clipping level of each output term: max strength of its rules.
    fn fire(&self, degrees: &[f64], strengths: &mut [f64]) {
        strengths.fill(0.0);
        let antecedents = self.flat.chunks_exact(self.inputs.len());
        for (rule, ante) in self.rules.iter().zip(antecedents) {
            let s = and(ante, degrees) * rule.weight;
            let level = &mut strengths[rule.consequent];
            if s > *level {
                *level = s;
            }
        }
    }

    /// Centroid of the aggregated set (see the module docs), or `None` when
    /// it has no area. `fired` is a buffer of at least `strengths.len()`.
    ///
    /// Segments without a clipping corner are summed in closed form for the
    /// uniform step h: area = h/2 Σ(y₀ + y₁), moment = h/2 Σ x₀(y₀ + y₁) +
    /// h²/6 Σ(y₀ + 2y₁); segments with corners are split at them.
    fn centroid(&self, strengths: &[f64], fired: &mut [usize]) -> Option<f64> {
        let nt = strengths.len();
        let (mut lo, mut hi, mut nf) = (usize::MAX, 0, 0);
        for ((t, &s), &(a, b)) in strengths.iter().enumerate().zip(&self.support) {
            if s > 0.0 {
                fired[nf] = t;
                nf += 1;
                lo = lo.min(a);
                hi = hi.max(b);
            }
        }
        if nf == 0 {
            return None;
        }
        let fired = &fired[..nf];
        let row = |k: usize| &self.sampled[k * nt..(k + 1) * nt];
        let mut prev = row(lo);
        let mut y0 = fired
            .iter()
            .fold(0.0, |m, &t| max(m, min(strengths[t], prev[t])));
        let (mut sum, mut sum_x, mut sum_w) = (0.0, 0.0, 0.0);
        let mut split = Centroid::default();
        for k in lo + 1..=hi {
            let next = row(k);
            let mut y1 = 0.0;
            let mut corner = false;
            for &t in fired {
                let (s, m0, m1) = (strengths[t], prev[t], next[t]);
                y1 = max(y1, min(s, m1));
                corner |= (m0 >= s) != (m1 >= s);
            }
            if corner {
                self.split_segment(k, strengths, fired, (prev, next), (y0, y1), &mut split);
            } else {
                let both = y0 + y1;
                sum += both;
                sum_x += self.grid[k - 1] * both;
                sum_w += y0 + 2.0 * y1;
            }
            (prev, y0) = (next, y1);
        }
        let h = self.step;
        let area = 0.5 * h * sum + split.area;
        let moment = 0.5 * h * sum_x + h * h / 6.0 * sum_w + split.moment;
        (area > 0.0).then(|| moment / area)
    }

    /// Adds segment `k − 1 … k` split at the clipping corners of the fired
    /// terms, in increasing order (a selection pass per corner: there are at
    /// most a few). `mu` are the sampled degrees at both ends, `y` the
    /// aggregated values there.
    fn split_segment(
        &self,
        k: usize,
        strengths: &[f64],
        fired: &[usize],
        mu: (&[f64], &[f64]),
        y: (f64, f64),
        acc: &mut Centroid,
    ) {
        let (x0, x1) = (self.grid[k - 1], self.grid[k]);
        let w = x1 - x0;
        let (mut xa, mut ya) = (x0, y.0);
        loop {
            let mut next = f64::INFINITY;
            for &t in fired {
                let (s, m0, m1) = (strengths[t], mu.0[t], mu.1[t]);
                if (m0 >= s) != (m1 >= s) {
                    let p = x0 + (s - m0) * w / (m1 - m0);
                    if p > xa && p < next {
                        next = p;
                    }
                }
            }
            if next >= x1 {
                break;
            }
            let yp = fired.iter().fold(0.0, |m, &t| {
                let (m0, m1) = (mu.0[t], mu.1[t]);
                let slope = (m1 - m0) / w;
                max(m, min(strengths[t], slope * (next - x0) + m0))
            });
            acc.add(xa, ya, next, yp);
            (xa, ya) = (next, yp);
        }
        acc.add(xa, ya, x1, y.1);
    }
}

/// Fuzzy AND of the degrees at `indices` (min; 1 for none).
#[inline]
fn and(indices: &[usize], degrees: &[f64]) -> f64 {
    indices.iter().fold(1.0, |m, &i| min(m, degrees[i]))
}

/// `a.min(b)` for non-NaN values, without NaN handling (hot loops).
#[inline]
fn min(a: f64, b: f64) -> f64 {
    if b < a {
        b
    } else {
        a
    }
}

/// `a.max(b)` for non-NaN values, without NaN handling (hot loops).
#[inline]
fn max(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// Running area and first moment of a piecewise-linear curve.
#[derive(Debug, Default)]
struct Centroid {
    area: f64,
    moment: f64,
}

impl Centroid {
    /// Adds the trapezoid under the segment (xa, ya)–(xb, yb): area
    /// w (ya + yb)/2, moment w (xa (ya + yb)/2 + w (ya + 2 yb)/6).
    #[inline]
    fn add(&mut self, xa: f64, ya: f64, xb: f64, yb: f64) {
        let w = xb - xa;
        let half = 0.5 * (ya + yb);
        self.area += w * half;
        self.moment += w * (xa * half + w * (ya + 2.0 * yb) / 6.0);
    }

    /// Centroid, or `None` for zero area.
    fn value(&self) -> Option<f64> {
        (self.area > 0.0).then(|| self.moment / self.area)
    }
}

/// Evenly spaced points of `[min, max]` (crate helper for grids).
pub(crate) fn linspace(min: f64, max: f64, n: usize) -> Vec<f64> {
    (0..n).map(|i| var_sample(min, max, n, i)).collect()
}
