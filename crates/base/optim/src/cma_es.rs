//! CMA-ES, the covariance matrix adaptation evolution strategy (Hansen &
//! Ostermeier 2001; the (μ/μ_w, λ) form, default constants and update
//! equations of Hansen 2016, "The CMA Evolution Strategy: A Tutorial",
//! arXiv:1604.00772, Table 1 and §B.2), seeded, on a box, ranking points by
//! the same [`Constraints`] rule as the Grey Wolf Optimizer, within a hard
//! evaluation budget, restarting with a doubled population (IPOP, Auger &
//! Hansen 2005) when a run stalls.
//!
//! Why it is here: a population search such as [`crate::minimize`] finds
//! the basin but creeps along a narrow curved valley or an active
//! constraint (the rope-shovel dig optimum sits on the dig-time bound and on
//! the end-height constraint, with the two path bends and the end height
//! coupled through the fill); CMA-ES learns the valley's shape in its
//! covariance and walks along it. Why by hand: the `cmaes` crate is
//! unconstrained (an `f64` objective only), unbounded, draws from its own
//! thread-local generator and pulls in a plotting stack; here the ranking is
//! Deb's rules, the box is kept by repair, and one ChaCha8 stream makes
//! every draw.
//!
//! # Box and repair
//! The search runs in the box normalised to [0, 1] per dimension. A sample
//! outside it is clamped to it, and the clamped point is both what is
//! evaluated and what enters the update (Lamarckian repair), so the mean
//! stays in the box and a bound optimum is reached exactly.
//!
//! # Restarts
//! A run ends when its step σ·max(√eig C) falls below `min_step`, or its
//! best has not improved for `10 + ⌈30 n / λ⌉` generations; the next starts
//! from a uniform random point of the box with the initial σ and twice the
//! population (IPOP), until the budget is spent. The first run starts from
//! the given point.

use std::cmp::Ordering;

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use rayon::prelude::*;

use crate::constraints::Constraints;
use crate::error::OptimError;
use crate::problem::{check_bounds, check_start, Evaluation, Problem};

/// Parameters of [`cma_es`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CmaParams {
    /// Most evaluations of the problem, ≥ 1.
    pub evaluations: usize,
    /// Initial step σ₀ as a share of each dimension's width, in (0, 1].
    /// Default 0.3 (a global search from the start point); 0.05 polishes.
    pub initial_step: f64,
    /// Offspring per generation λ of the first run; 0 for Hansen's default
    /// 4 + ⌊3 ln n⌋. Default 0.
    pub population: usize,
    /// A run stops when σ·max(√eig C) falls below this share of the width.
    /// Default 1e-9.
    pub min_step: f64,
    /// How two points are ranked.
    pub constraints: Constraints,
    /// Seed of the one random generator.
    pub seed: u64,
    /// Evaluate each generation's offspring on rayon's thread pool. The
    /// offspring are drawn first, in order, so the result does not depend
    /// on it. Default true.
    #[serde(default = "parallel_default")]
    pub parallel: bool,
}

fn parallel_default() -> bool {
    true
}

impl Default for CmaParams {
    fn default() -> Self {
        Self {
            evaluations: 5000,
            initial_step: 0.3,
            population: 0,
            min_step: 1e-9,
            constraints: Constraints::FeasibilityRules,
            seed: 0,
            parallel: true,
        }
    }
}

/// What [`cma_es`] returns.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CmaResult {
    /// The best point evaluated (or the start, if nothing beat it).
    pub best: Vec<f64>,
    /// Its evaluation.
    pub best_eval: Evaluation,
    /// Evaluations made.
    pub evaluations: usize,
    /// Runs made (1 + restarts).
    pub runs: usize,
    /// The best so far after each generation, for convergence plots.
    pub history: Vec<CmaGeneration>,
}

/// One generation of [`cma_es`]: the best point so far after it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CmaGeneration {
    /// Evaluations made so far.
    pub evaluations: usize,
    /// The run it belongs to (1 = from the start point, then restarts).
    pub run: usize,
    /// Objective of the best point so far.
    pub best_objective: f64,
    /// Its violation.
    pub best_violation: f64,
}

/// Minimise `problem` by CMA-ES from `start` (evaluated as `start_eval`,
/// which counts as the best so far), see the module docs. Same seed, same
/// result.
///
/// ```
/// use autoshovel_optim::{cma_es, CmaParams, Evaluation, FnProblem, Problem};
/// // A narrow rotated valley: Rosenbrock in 4-D on [−2, 2]⁴, optimum at 1.
/// let p = FnProblem::new(vec![(-2.0, 2.0); 4], |x: &[f64]| {
///     Evaluation::feasible(x.windows(2).map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2)).sum())
/// });
/// let start = vec![-1.5; 4];
/// let r = cma_es(&p, &start, p.evaluate(&start), &CmaParams { evaluations: 8000, ..CmaParams::default() })?;
/// assert!(r.best_eval.objective < 1e-8, "{}", r.best_eval.objective);
/// # Ok::<(), autoshovel_optim::OptimError>(())
/// ```
pub fn cma_es<P: Problem + ?Sized>(
    problem: &P,
    start: &[f64],
    start_eval: Evaluation,
    params: &CmaParams,
) -> Result<CmaResult, OptimError> {
    let bounds = problem.bounds();
    validate(bounds, start, params)?;
    let n = bounds.len();
    let cmp = params.constraints;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);
    let to_unit = |x: &[f64]| -> DVector<f64> {
        DVector::from_iterator(
            n,
            x.iter()
                .zip(bounds)
                .map(|(&v, &(lo, hi))| ((v - lo) / (hi - lo)).clamp(0.0, 1.0)),
        )
    };
    let from_unit = |u: &DVector<f64>| -> Vec<f64> {
        u.iter()
            .zip(bounds)
            .map(|(&u, &(lo, hi))| {
                if u <= 0.0 {
                    lo
                } else if u >= 1.0 {
                    hi
                } else {
                    lo + u * (hi - lo)
                }
            })
            .collect()
    };

    let mut best_u = to_unit(start);
    let mut best_eval = start_eval;
    let mut improved = false;
    let mut used = 0;
    let mut runs = 0;
    let mut history = Vec::new();
    let mut lambda = if params.population > 0 {
        params.population.max(2)
    } else {
        4 + (3.0 * (n as f64).ln()).floor() as usize
    };
    while used < params.evaluations {
        runs += 1;
        let from = if runs == 1 {
            best_u.clone()
        } else {
            DVector::from_iterator(n, (0..n).map(|_| rng.gen::<f64>()))
        };
        let mut run = Run::new(n, lambda, from, params.initial_step);
        let stall_limit = 10 + (30 * n).div_ceil(lambda);
        let mut since_best = 0;
        let mut run_best = Evaluation::new(f64::INFINITY, f64::INFINITY);
        loop {
            if used >= params.evaluations {
                break;
            }
            let take = lambda.min(params.evaluations - used);
            // Draw the generation in order, then evaluate it (in parallel
            // when asked: the draws, and so the result, do not change).
            let drawn: Vec<(DVector<f64>, Vec<f64>)> = (0..take)
                .map(|_| {
                    let z =
                        DVector::from_iterator(n, (0..n).map(|_| StandardNormal.sample(&mut rng)));
                    let x = (&run.mean + run.sigma * (&run.bd * z)).map(|v| v.clamp(0.0, 1.0));
                    let at = from_unit(&x);
                    (x, at)
                })
                .collect();
            let evals: Vec<Evaluation> = if params.parallel {
                drawn
                    .par_iter()
                    .map(|(_, at)| problem.evaluate(at))
                    .collect()
            } else {
                drawn.iter().map(|(_, at)| problem.evaluate(at)).collect()
            };
            let mut offspring: Vec<(DVector<f64>, Evaluation)> = Vec::with_capacity(take);
            for ((x, at), e) in drawn.into_iter().zip(evals) {
                e.check(used, 0, || at)?;
                used += 1;
                offspring.push((x, e));
            }
            offspring.sort_by(|a, b| cmp.compare(&a.1, &b.1));
            if cmp.compare(&offspring[0].1, &best_eval) == Ordering::Less {
                best_eval = offspring[0].1;
                best_u = offspring[0].0.clone();
                improved = true;
            }
            history.push(CmaGeneration {
                evaluations: used,
                run: runs,
                best_objective: best_eval.objective,
                best_violation: best_eval.violation,
            });
            if cmp.compare(&offspring[0].1, &run_best) == Ordering::Less {
                run_best = offspring[0].1;
                since_best = 0;
            } else {
                since_best += 1;
            }
            if take < lambda {
                break; // the budget ended mid-generation
            }
            run.update(&offspring);
            if run.step() < params.min_step || since_best > stall_limit || !run.sigma.is_finite() {
                break;
            }
        }
        lambda *= 2;
    }
    Ok(CmaResult {
        best: if improved {
            from_unit(&best_u)
        } else {
            start.to_vec()
        },
        best_eval,
        evaluations: used,
        runs,
        history,
    })
}

/// The state of one CMA-ES run (Hansen 2016, Table 1 and §B.2).
struct Run {
    mean: DVector<f64>,
    sigma: f64,
    c: DMatrix<f64>,
    /// B·D, the square root of C the samples are drawn through.
    bd: DMatrix<f64>,
    /// C^(−1/2), for the step-size path.
    inv_sqrt_c: DMatrix<f64>,
    p_sigma: DVector<f64>,
    p_c: DVector<f64>,
    weights: Vec<f64>,
    mu_eff: f64,
    c_sigma: f64,
    d_sigma: f64,
    c_c: f64,
    c_1: f64,
    c_mu: f64,
    chi_n: f64,
    generation: usize,
}

impl Run {
    fn new(n: usize, lambda: usize, mean: DVector<f64>, sigma: f64) -> Self {
        let nf = n as f64;
        let mu = lambda / 2;
        let raw: Vec<f64> = (0..mu)
            .map(|i| ((lambda as f64 + 1.0) / 2.0).ln() - ((i + 1) as f64).ln())
            .collect();
        let sum: f64 = raw.iter().sum();
        let weights: Vec<f64> = raw.iter().map(|w| w / sum).collect();
        let mu_eff = 1.0 / weights.iter().map(|w| w * w).sum::<f64>();
        let c_sigma = (mu_eff + 2.0) / (nf + mu_eff + 5.0);
        let d_sigma = 1.0 + 2.0 * (((mu_eff - 1.0) / (nf + 1.0)).sqrt() - 1.0).max(0.0) + c_sigma;
        let c_c = (4.0 + mu_eff / nf) / (nf + 4.0 + 2.0 * mu_eff / nf);
        let c_1 = 2.0 / ((nf + 1.3).powi(2) + mu_eff);
        let c_mu =
            (1.0 - c_1).min(2.0 * (mu_eff - 2.0 + 1.0 / mu_eff) / ((nf + 2.0).powi(2) + mu_eff));
        Self {
            mean,
            sigma,
            c: DMatrix::identity(n, n),
            bd: DMatrix::identity(n, n),
            inv_sqrt_c: DMatrix::identity(n, n),
            p_sigma: DVector::zeros(n),
            p_c: DVector::zeros(n),
            weights,
            mu_eff,
            c_sigma,
            d_sigma,
            c_c,
            c_1,
            c_mu,
            chi_n: nf.sqrt() * (1.0 - 1.0 / (4.0 * nf) + 1.0 / (21.0 * nf * nf)),
            generation: 0,
        }
    }

    /// σ·max(√eig C): the largest step of the next generation.
    fn step(&self) -> f64 {
        let max_d = self
            .bd
            .column_iter()
            .map(|c| c.norm())
            .fold(0.0_f64, f64::max);
        self.sigma * max_d
    }

    /// One generation's update from the offspring, best first.
    fn update(&mut self, ranked: &[(DVector<f64>, Evaluation)]) {
        let n = self.mean.len();
        let nf = n as f64;
        self.generation += 1;
        let old = self.mean.clone();
        let ys: Vec<DVector<f64>> = ranked[..self.weights.len()]
            .iter()
            .map(|(x, _)| (x - &old) / self.sigma)
            .collect();
        let y_w = ys
            .iter()
            .zip(&self.weights)
            .fold(DVector::zeros(n), |s, (y, &w)| s + y * w);
        self.mean = &old + self.sigma * &y_w;
        // Step-size path and σ.
        self.p_sigma = (1.0 - self.c_sigma) * &self.p_sigma
            + (self.c_sigma * (2.0 - self.c_sigma) * self.mu_eff).sqrt()
                * (&self.inv_sqrt_c * &y_w);
        let ps_norm = self.p_sigma.norm();
        self.sigma *= ((self.c_sigma / self.d_sigma) * (ps_norm / self.chi_n - 1.0)).exp();
        // Covariance path (stalled while ‖p_σ‖ is large) and C.
        let h_sigma = ps_norm
            / (1.0 - (1.0 - self.c_sigma).powi(2 * self.generation as i32)).sqrt()
            < (1.4 + 2.0 / (nf + 1.0)) * self.chi_n;
        let h = if h_sigma { 1.0 } else { 0.0 };
        self.p_c = (1.0 - self.c_c) * &self.p_c
            + h * (self.c_c * (2.0 - self.c_c) * self.mu_eff).sqrt() * &y_w;
        let rank_mu = ys
            .iter()
            .zip(&self.weights)
            .fold(DMatrix::zeros(n, n), |s, (y, &w)| s + w * y * y.transpose());
        let delta_h = (1.0 - h) * self.c_c * (2.0 - self.c_c);
        self.c = (1.0 - self.c_1 - self.c_mu) * &self.c
            + self.c_1 * (&self.p_c * self.p_c.transpose() + delta_h * &self.c)
            + self.c_mu * rank_mu;
        // Keep C symmetric and positive; refresh its square roots.
        self.c = 0.5 * (&self.c + self.c.transpose());
        let eig = SymmetricEigen::new(self.c.clone());
        let d = eig.eigenvalues.map(|v| v.max(1e-20).sqrt());
        self.bd = &eig.eigenvectors * DMatrix::from_diagonal(&d);
        self.inv_sqrt_c = &eig.eigenvectors
            * DMatrix::from_diagonal(&d.map(|v| 1.0 / v))
            * eig.eigenvectors.transpose();
    }
}

fn validate(bounds: &[(f64, f64)], start: &[f64], params: &CmaParams) -> Result<(), OptimError> {
    check_bounds(bounds)?;
    check_start(0, start, bounds.len())?;
    if params.evaluations == 0 {
        return Err(OptimError::ZeroIterations);
    }
    if !(params.initial_step > 0.0 && params.initial_step <= 1.0) {
        return Err(OptimError::BadStep {
            name: "initial_step",
            value: params.initial_step,
        });
    }
    if !(params.min_step > 0.0 && params.min_step.is_finite()) {
        return Err(OptimError::BadStep {
            name: "min_step",
            value: params.min_step,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FnProblem;

    #[test]
    fn walks_along_an_active_oblique_constraint() {
        // min x + y subject to x + 2y ≥ 1 on [0, 1]²: optimum (0, 0.5), value 0.5
        // (coordinate polls stall on this boundary).
        let p = FnProblem::new(vec![(0.0, 1.0); 2], |x: &[f64]| {
            Evaluation::new(x[0] + x[1], (1.0 - x[0] - 2.0 * x[1]).max(0.0))
        });
        let start = vec![0.6, 0.6];
        let r = cma_es(&p, &start, p.evaluate(&start), &CmaParams::default()).unwrap();
        assert!(r.best_eval.is_feasible());
        assert!((r.best_eval.objective - 0.5).abs() < 1e-6, "{r:?}");
        assert_eq!(r.best[0], 0.0);
    }

    #[test]
    fn same_seed_same_result_and_the_budget_holds() {
        let p = FnProblem::new(vec![(-3.0, 3.0); 5], |x: &[f64]| {
            Evaluation::feasible(x.iter().map(|v| v * v - 2.0 * (3.0 * v).cos()).sum())
        });
        let start = vec![2.5; 5];
        let params = CmaParams {
            evaluations: 777,
            seed: 5,
            ..CmaParams::default()
        };
        let a = cma_es(&p, &start, p.evaluate(&start), &params).unwrap();
        let b = cma_es(&p, &start, p.evaluate(&start), &params).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.evaluations, 777);
        // Evaluated in parallel or not, the same run.
        let serial = CmaParams {
            parallel: false,
            ..params
        };
        assert_eq!(cma_es(&p, &start, p.evaluate(&start), &serial).unwrap(), a);
        assert_eq!(p.evaluate(&a.best), a.best_eval);
    }

    #[test]
    fn the_start_is_kept_when_nothing_beats_it() {
        let p = FnProblem::new(vec![(-1.0, 1.0)], |x: &[f64]| {
            Evaluation::feasible(x[0] * x[0])
        });
        let r = cma_es(
            &p,
            &[0.0],
            Evaluation::feasible(0.0),
            &CmaParams {
                evaluations: 50,
                ..CmaParams::default()
            },
        )
        .unwrap();
        assert_eq!(r.best, vec![0.0]);
    }
}
