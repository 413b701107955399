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
//! moves u by at most ≈ 0.2 rpm from the continuous centroid (measured
//! against [`MamdaniSystem::infer_dense`] by the tests); choose a resolution
//! that puts every breakpoint on a sample (181 or 241 there) to remove the
//! first effect.
//!
//! # Hot path
//! Construction samples the output terms once and stores, for every
//! segment between two samples, the terms that are non-zero on it. An
//! inference then costs one membership evaluation per input term, one min
//! per antecedent, and one pass over the segments spanned by the terms that
//! fired, with no allocation ([`MamdaniSystem::infer`] keeps its buffers on
//! the stack for up to 64 terms, [`MamdaniSystem::infer_with`] reuses a
//! [`Scratch`]).

use serde::{Deserialize, Serialize};

use crate::variable::var_sample;
use crate::{FuzzyError, Rule, Variable};

/// Default number of output samples.
pub const DEFAULT_RESOLUTION: usize = 201;

/// Term counts up to which [`MamdaniSystem::infer`] needs no heap buffers.
const STACK_TERMS: usize = 64;

/// An output term that is non-zero on one segment, with its sampled degrees
/// at the segment's two ends.
#[derive(Debug, Clone, Copy)]
struct SegTerm {
    term: usize,
    mu0: f64,
    mu1: f64,
}

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
    /// Segment k's terms are `seg_terms[seg_start[k]..seg_start[k + 1]]`.
    seg_start: Vec<usize>,
    seg_terms: Vec<SegTerm>,
    /// Per output term, the half-open range of segments it is non-zero on.
    term_segs: Vec<(usize, usize)>,
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
}

impl Scratch {
    fn fit(&mut self, degrees: usize, strengths: usize) {
        if self.degrees.len() != degrees {
            self.degrees.resize(degrees, 0.0);
        }
        if self.strengths.len() != strengths {
            self.strengths.resize(strengths, 0.0);
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
        let sampled: Vec<Vec<f64>> = output
            .terms
            .iter()
            .map(|(_, mf)| grid.iter().map(|&y| mf.degree(y)).collect())
            .collect();
        let n_terms = output.terms.len();
        let mut term_segs = vec![(usize::MAX, 0); n_terms];
        let mut seg_start = Vec::with_capacity(resolution);
        let mut seg_terms = Vec::new();
        for k in 0..resolution - 1 {
            seg_start.push(seg_terms.len());
            for (t, mu) in sampled.iter().enumerate() {
                let (mu0, mu1) = (mu[k], mu[k + 1]);
                if mu0 > 0.0 || mu1 > 0.0 {
                    seg_terms.push(SegTerm { term: t, mu0, mu1 });
                    let range = &mut term_segs[t];
                    range.0 = range.0.min(k);
                    range.1 = range.1.max(k + 1);
                }
            }
        }
        seg_start.push(seg_terms.len());
        for (t, range) in term_segs.iter().enumerate() {
            if range.0 >= range.1 {
                return Err(FuzzyError::BadMembership {
                    variable: output.name.clone(),
                    term: output.terms[t].0.clone(),
                    why: "no output sample has a positive degree; raise the resolution",
                });
            }
        }

        Ok(MamdaniSystem {
            inputs,
            output,
            rules,
            resolution,
            offsets,
            flat,
            grid,
            seg_start,
            seg_terms,
            term_segs,
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
            Ok(self.run(x, &mut degrees[..n_in], &mut strengths[..n_out]))
        } else {
            let mut scratch = self.scratch();
            Ok(self.run(x, &mut scratch.degrees, &mut scratch.strengths))
        }
    }

    /// [`MamdaniSystem::infer`] with caller-owned buffers: never allocates
    /// once `scratch` fits this system (see [`Scratch`]).
    pub fn infer_with(&self, x: &[f64], scratch: &mut Scratch) -> Result<f64, FuzzyError> {
        self.check_inputs(x)?;
        scratch.fit(self.offsets[self.inputs.len()], self.output.terms.len());
        Ok(self.run(x, &mut scratch.degrees, &mut scratch.strengths))
    }

    /// [`MamdaniSystem::infer`] plus every intermediate value (allocates).
    pub fn infer_traced(&self, x: &[f64]) -> Result<Trace, FuzzyError> {
        self.check_inputs(x)?;
        let mut scratch = self.scratch();
        self.fuzzify(x, &mut scratch.degrees);
        self.fire(&scratch.degrees, &mut scratch.strengths);
        let defuzzified = self.centroid(&scratch.strengths);
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
    fn run(&self, x: &[f64], degrees: &mut [f64], strengths: &mut [f64]) -> f64 {
        self.fuzzify(x, degrees);
        self.fire(degrees, strengths);
        self.crisp(self.centroid(strengths))
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
        let strength = self.flat[r * n..(r + 1) * n]
            .iter()
            .fold(1.0f64, |m, &i| m.min(degrees[i]));
        strength * self.rules[r].weight
    }

    /// Clipping level of each output term: max strength of its rules.
    fn fire(&self, degrees: &[f64], strengths: &mut [f64]) {
        strengths.fill(0.0);
        for (r, rule) in self.rules.iter().enumerate() {
            let s = self.rule_strength(r, degrees);
            let level = &mut strengths[rule.consequent];
            if s > *level {
                *level = s;
            }
        }
    }

    /// Centroid of the aggregated set (see the module docs), or `None` when
    /// it has no area.
    fn centroid(&self, strengths: &[f64]) -> Option<f64> {
        let (mut lo, mut hi) = (usize::MAX, 0);
        for (&s, &(a, b)) in strengths.iter().zip(&self.term_segs) {
            if s > 0.0 {
                lo = lo.min(a);
                hi = hi.max(b);
            }
        }
        if lo >= hi {
            return None;
        }
        let clipped = |e: &SegTerm, mu: f64| strengths[e.term].min(mu);
        let mut acc = Centroid::default();
        let mut y0 = self
            .segment(lo)
            .iter()
            .fold(0.0f64, |m, e| m.max(clipped(e, e.mu0)));
        for k in lo..hi {
            let (x0, x1) = (self.grid[k], self.grid[k + 1]);
            let seg = self.segment(k);
            let mut y1 = 0.0f64;
            let mut corner = false;
            for e in seg {
                y1 = y1.max(clipped(e, e.mu1));
                corner |= crosses(e, strengths[e.term]);
            }
            if corner {
                // Insert the clipping corners in increasing order (a
                // selection pass per corner: there are at most a few).
                let w = x1 - x0;
                let (mut xa, mut ya) = (x0, y0);
                loop {
                    let mut next = f64::INFINITY;
                    for e in seg {
                        let s = strengths[e.term];
                        if crosses(e, s) {
                            let p = x0 + (s - e.mu0) * w / (e.mu1 - e.mu0);
                            if p > xa && p < next {
                                next = p;
                            }
                        }
                    }
                    if !(next < x1) {
                        break;
                    }
                    let yp = seg.iter().fold(0.0f64, |m, e| {
                        let slope = (e.mu1 - e.mu0) / w;
                        m.max(clipped(e, slope * (next - x0) + e.mu0))
                    });
                    acc.add(xa, ya, next, yp);
                    (xa, ya) = (next, yp);
                }
                acc.add(xa, ya, x1, y1);
            } else {
                acc.add(x0, y0, x1, y1);
            }
            y0 = y1;
        }
        acc.value()
    }

    /// Output terms non-zero on segment `k`.
    fn segment(&self, k: usize) -> &[SegTerm] {
        &self.seg_terms[self.seg_start[k]..self.seg_start[k + 1]]
    }
}

/// Whether the term's interpolated membership crosses its clipping level
/// `s > 0` inside the segment (the scikit-fuzzy `mf >= level` test).
#[inline]
fn crosses(e: &SegTerm, s: f64) -> bool {
    s > 0.0 && ((e.mu0 >= s) != (e.mu1 >= s))
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
