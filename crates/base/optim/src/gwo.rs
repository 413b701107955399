//! The Grey Wolf Optimizer (Mirjalili, Mirjalili & Lewis 2014, "Grey Wolf
//! Optimizer", Adv. Eng. Softw. 69:46–61, eqs. 3.1–3.7; rope-shovel paper
//! §4.5, [RS eq. 37]), seeded and deterministic, with good-point-set or random
//! initialisation, warm starts, Deb's feasibility rules or a penalty for
//! constraints, and optional parallel evaluation.
//!
//! The exact rules (schedule, leaders, draw order, origin bias) are in the
//! docs of [`minimize`].

use std::cmp::Ordering;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::constraints::Constraints;
use crate::error::OptimError;
use crate::good_point_set::good_point_set;
use crate::problem::{check_bounds, check_start, Evaluation, Problem};

/// How the initial pack is placed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Init {
    /// The deterministic good point set of the rope-shovel paper's §4.5
    /// (see [`crate::good_point_set()`]); the seed then only drives the
    /// iterations.
    #[default]
    GoodPointSet,
    /// Uniform random points in the box (Mirjalili et al. 2014).
    Random,
}

impl Init {
    /// The placement's name as summaries print it: `good-point-set` or `random`.
    pub fn name(self) -> &'static str {
        match self {
            Init::GoodPointSet => "good-point-set",
            Init::Random => "random",
        }
    }
}

/// Parameters of [`minimize`]. `Default` is Mirjalili et al. 2014's
/// benchmark setting ([`GwoParams::mirjalili_2014`]); an application's own
/// preset lives with the application (the dig planner's in
/// `autoshovel_rope_shovel_dig::gwo_preset`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GwoParams {
    /// Number of wolves, ≥ 4 (α, β, δ and at least one ω).
    pub population: usize,
    /// Number of position updates T, ≥ 1; each is followed by one
    /// evaluation of the whole pack.
    pub iterations: usize,
    /// Placement of the initial pack.
    pub init: Init,
    /// Constraint handling.
    pub constraints: Constraints,
    /// Seed of the one random generator.
    pub seed: u64,
    /// Evaluate the wolves on rayon's thread pool (the result does not
    /// depend on it). Worth it when one evaluation costs more than a few
    /// microseconds.
    pub parallel: bool,
}

impl Default for GwoParams {
    fn default() -> Self {
        Self::mirjalili_2014()
    }
}

impl GwoParams {
    /// Mirjalili et al. 2014's benchmark setting (§4): 30 wolves, 500
    /// iterations, random start; feasibility rules, seed 0, parallel
    /// evaluation.
    pub fn mirjalili_2014() -> Self {
        Self {
            population: 30,
            iterations: 500,
            init: Init::Random,
            constraints: Constraints::FeasibilityRules,
            seed: 0,
            parallel: true,
        }
    }

    /// A pack of `population` wolves run for `iterations` from `init`,
    /// the rest as [`GwoParams::default`].
    pub fn pack(population: usize, iterations: usize, init: Init) -> Self {
        Self {
            population,
            iterations,
            init,
            ..Self::default()
        }
    }
}

/// Summary of the pack after one iteration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Generation {
    /// 0 for the initial pack, then 1 ..= iterations.
    pub iteration: usize,
    /// Objective of α*, the best point so far.
    pub best_objective: f64,
    /// Violation of α*.
    pub best_violation: f64,
    /// Mean objective of the current wolves (may be infinite).
    pub mean_objective: f64,
    /// Share of the current wolves that are feasible, in [0, 1].
    pub feasible_share: f64,
}

/// What [`minimize`] returns.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GwoResult {
    /// α*: the best point evaluated.
    pub best: Vec<f64>,
    /// Its evaluation.
    pub best_eval: Evaluation,
    /// `iterations + 1` entries: the initial pack, then one per iteration.
    pub history: Vec<Generation>,
    /// Number of calls to [`Problem::evaluate`]: population × (iterations + 1).
    pub evaluations: usize,
    /// The final pack for a warm start: the last wolves sorted best first,
    /// with `best` put in front (in place of the worst wolf) when it is not
    /// among them, so `population[0]` is always `best`.
    pub population: Vec<(Vec<f64>, Evaluation)>,
}

/// Minimises `problem` with the Grey Wolf Optimizer ([RS eq. 37]).
///
/// `warm_start` wolves (clamped to the bounds) replace the first members of
/// the initial pack; the rest come from [`GwoParams::init`]. Everything is
/// validated before the first evaluation; a NaN objective, or a NaN or
/// negative violation, stops the run with an error naming the wolf and the
/// iteration.
///
/// # Iteration t = 0, …, T − 1 (T = `iterations`)
///
/// ```text
/// a   = 2 (1 − t/T)                          decreases linearly 2 → 0 (eq. 3.3)
/// for every wolf X, every dimension j, every leader L ∈ (α, β, δ):
///     r1, r2 ~ U[0, 1)                        fresh for each (wolf, j, L)
///     A = 2a·r1 − a,  C = 2·r2                (eqs. 3.3–3.4)
///     D_L = |C·X_L,j − X_j|                   (eq. 3.5)
///     X_L' = X_L,j − A·D_L                    (eq. 3.6)
/// X_j ← clamp((X_α' + X_β' + X_δ') / 3, lower_j, upper_j)   (eq. 3.7 = [RS eq. 37])
/// ```
///
/// then every wolf is evaluated and the leaders are chosen again.
/// a = 2(1 − t/T) is the schedule of Mirjalili's reference code; its last
/// step uses a = 2/T and a reaches 0 at t = T.
///
/// # Leaders (what exactly is kept)
///
/// α, β, δ are the three best *current* wolves, ranked by
/// [`Constraints::compare`] (ties: lower wolf index first), chosen afresh
/// after every evaluation; a leader moves like every other wolf. Apart from
/// them the best point ever evaluated, α*, is kept: it replaces α* only when
/// strictly better, it is what [`GwoResult::best`] returns and what the
/// history reports, so the returned best never gets worse from one
/// iteration to the next. α* does not steer the pack.
///
/// Mirjalili's reference code instead keeps its leaders across iterations
/// (replacing each only by a better wolf, without shifting α → β → δ).
/// Measured over 30 seeds on the paper's 30-D setting (random start), that
/// variant reproduces the paper's sphere and Ackley means (1.4e−27 and
/// 9.9e−14 against the published 6.6e−28 and 1.1e−13) but leaves Rastrigin
/// at 2.3 (published 0.31); the current-pack leaders used here reach
/// 3.6e−31, 1.7e−14 and 0 on those three, and 27.3 on Rosenbrock (that
/// variant 27.2, published 26.8).
///
/// # Origin bias: put the box around 0
///
/// [RS eq. 37] is equivariant under scaling about the origin but not under
/// translation: C·X_L scales the leader about 0, so the steps stay
/// proportional to |X_L| rather than to the distance to the optimum. GWO
/// therefore excels when the optimum is at the origin (all four classic
/// benchmarks) and does far worse elsewhere (Niu, Niu & Chang 2019, "The
/// defect of the Grey Wolf optimization algorithm and its verification
/// method", Knowl.-Based Syst. 171:37–43). Measured here, 30-D, 30 wolves ×
/// 500 iterations, mean over 10 seeds: sphere 3e−31 at 0 but 1.9e3 with
/// the optimum at 37 on [−100, 100]; Rastrigin 0 against 145 shifted by
/// 1.7. And a 5-D sphere centred at 11.85 on [9, 15]^5 (50 × 100) ends
/// 1.9e−3 from its optimum in raw units but 3.2e−7 when the same problem
/// is posed on [−1, 1]^5 and mapped. Callers should pose their variables
/// on a box centred at 0 (e.g. [−1, 1] per dimension, mapped inside
/// `evaluate`); [`minimize`] does not do it for them, so that it stays the
/// published algorithm.
///
/// # Random draws
///
/// One [`ChaCha8Rng`] seeded from [`GwoParams::seed`] makes every draw, on
/// the calling thread, in a fixed order: random initialisation (wolf by
/// wolf, dimension by dimension), then per iteration wolf by wolf,
/// dimension by dimension, (r1, r2) for α, β, δ in turn. Evaluations (the
/// only parallel part) draw nothing, so a result is bit-identical with
/// `parallel` on or off, on any number of threads, and across runs.
///
/// # Example
///
/// ```
/// use autoshovel_optim::{benchmarks::Benchmark, minimize, GwoParams};
///
/// let sphere = Benchmark::Sphere.problem(5);
/// let params = GwoParams { population: 50, iterations: 200, ..GwoParams::default() };
/// let res = minimize(&sphere, &params, &[])?;
/// assert!(res.best_eval.objective < 1e-12);
/// assert_eq!(res.evaluations, 50 * 201);
/// # Ok::<(), autoshovel_optim::OptimError>(())
/// ```
pub fn minimize<P: Problem + ?Sized>(
    problem: &P,
    params: &GwoParams,
    warm_start: &[Vec<f64>],
) -> Result<GwoResult, OptimError> {
    let bounds = problem.bounds();
    validate(bounds, params, warm_start)?;
    let d = bounds.len();
    let n = params.population;
    let cmp = params.constraints;
    let mut rng = ChaCha8Rng::seed_from_u64(params.seed);

    // Initial pack, flat: wolf i is x[i·d .. (i + 1)·d].
    let mut x: Vec<f64> = match params.init {
        Init::GoodPointSet => good_point_set(n, bounds).concat(),
        Init::Random => {
            let mut x = Vec::with_capacity(n * d);
            for _ in 0..n {
                for &(lo, hi) in bounds {
                    x.push(lo + rng.gen::<f64>() * (hi - lo));
                }
            }
            x
        }
    };
    for (w, wolf) in warm_start.iter().enumerate() {
        for (k, (&v, &(lo, hi))) in wolf.iter().zip(bounds).enumerate() {
            x[w * d + k] = v.clamp(lo, hi);
        }
    }
    let mut evals = vec![Evaluation::feasible(0.0); n];
    evaluate(problem, &x, d, &mut evals, params.parallel, 0)?;

    // Leaders α, β, δ (positions 3·d, flat) and the best ever, α*.
    let mut lead_x = vec![0.0; 3 * d];
    let mut order = rank(&evals, &cmp);
    for (slot, &w) in order[..3].iter().enumerate() {
        lead_x[slot * d..(slot + 1) * d].copy_from_slice(&x[w * d..(w + 1) * d]);
    }
    let mut best = x[order[0] * d..(order[0] + 1) * d].to_vec();
    let mut best_eval = evals[order[0]];
    let mut history = Vec::with_capacity(params.iterations + 1);
    history.push(generation(0, &best_eval, &evals));

    let t_max = params.iterations;
    for t in 0..t_max {
        let a = 2.0 * (1.0 - t as f64 / t_max as f64);
        for wolf in x.chunks_exact_mut(d) {
            for (j, (xj, &(lo, hi))) in wolf.iter_mut().zip(bounds).enumerate() {
                let mut sum = 0.0;
                for l in 0..3 {
                    let r1: f64 = rng.gen();
                    let r2: f64 = rng.gen();
                    let big_a = 2.0 * a * r1 - a;
                    let c = 2.0 * r2;
                    let leader = lead_x[l * d + j];
                    // D_L and X_L' of [RS eq. 37] (Mirjalili eqs. 3.5–3.6).
                    sum += leader - big_a * (c * leader - *xj).abs();
                }
                *xj = (sum / 3.0).clamp(lo, hi); // [RS eq. 37]: the mean of X_1, X_2, X_3
            }
        }
        evaluate(problem, &x, d, &mut evals, params.parallel, t + 1)?;
        order = rank(&evals, &cmp);
        for (slot, &w) in order[..3].iter().enumerate() {
            lead_x[slot * d..(slot + 1) * d].copy_from_slice(&x[w * d..(w + 1) * d]);
        }
        if cmp.compare(&evals[order[0]], &best_eval) == Ordering::Less {
            best.copy_from_slice(&x[order[0] * d..(order[0] + 1) * d]);
            best_eval = evals[order[0]];
        }
        history.push(generation(t + 1, &best_eval, &evals));
    }

    // Final pack: the last wolves best first, α* in front (dropping the
    // worst wolf) when no wolf equals it.
    let mut population: Vec<(Vec<f64>, Evaluation)> = order
        .iter()
        .map(|&w| (x[w * d..(w + 1) * d].to_vec(), evals[w]))
        .collect();
    if population[0].0 != best {
        population.pop();
        population.insert(0, (best.clone(), best_eval));
    }
    Ok(GwoResult {
        best,
        best_eval,
        history,
        evaluations: n * (t_max + 1),
        population,
    })
}

/// Checks bounds, parameters and warm starts before anything runs.
fn validate(
    bounds: &[(f64, f64)],
    params: &GwoParams,
    warm_start: &[Vec<f64>],
) -> Result<(), OptimError> {
    check_bounds(bounds)?;
    if params.population < 4 {
        return Err(OptimError::PopulationTooSmall {
            population: params.population,
        });
    }
    if params.iterations == 0 {
        return Err(OptimError::ZeroIterations);
    }
    if let Constraints::Penalty { weight } = params.constraints {
        if !(weight.is_finite() && weight >= 0.0) {
            return Err(OptimError::BadPenaltyWeight { weight });
        }
    }
    if warm_start.len() > params.population {
        return Err(OptimError::TooManyWarmStarts {
            given: warm_start.len(),
            population: params.population,
        });
    }
    for (wolf, w) in warm_start.iter().enumerate() {
        check_start(wolf, w, bounds.len())?;
    }
    Ok(())
}

/// Evaluates every wolf into `evals` (in parallel if asked), then checks
/// the values in wolf order so the reported wolf does not depend on
/// threading.
fn evaluate<P: Problem + ?Sized>(
    problem: &P,
    x: &[f64],
    d: usize,
    evals: &mut [Evaluation],
    parallel: bool,
    iteration: usize,
) -> Result<(), OptimError> {
    if parallel {
        evals
            .par_iter_mut()
            .zip(x.par_chunks_exact(d))
            .for_each(|(e, xi)| *e = problem.evaluate(xi));
    } else {
        for (e, xi) in evals.iter_mut().zip(x.chunks_exact(d)) {
            *e = problem.evaluate(xi);
        }
    }
    for (wolf, e) in evals.iter().enumerate() {
        e.check(iteration, wolf, || x[wolf * d..(wolf + 1) * d].to_vec())?;
    }
    Ok(())
}

/// Wolf indices sorted best first; the sort is stable, so ties keep the
/// lower index first.
fn rank(evals: &[Evaluation], cmp: &Constraints) -> Vec<usize> {
    let mut order: Vec<usize> = (0..evals.len()).collect();
    order.sort_by(|&a, &b| cmp.compare(&evals[a], &evals[b]));
    order
}

/// The history entry for one iteration.
fn generation(iteration: usize, alpha: &Evaluation, evals: &[Evaluation]) -> Generation {
    let n = evals.len() as f64;
    Generation {
        iteration,
        best_objective: alpha.objective,
        best_violation: alpha.violation,
        mean_objective: evals.iter().map(|e| e.objective).sum::<f64>() / n,
        feasible_share: evals.iter().filter(|e| e.is_feasible()).count() as f64 / n,
    }
}
