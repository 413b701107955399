//! What `minimize` promises beside quality: the evaluation count, the
//! history, the never-worsening best, the final pack, warm starts, bounds,
//! and an error (never a panic) for every bad input.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use autoshovel_optim::benchmarks::Benchmark;
use autoshovel_optim::{
    good_point_set, minimize, Constraints, Evaluation, FnProblem, GwoParams, Init, OptimError,
    Problem,
};

#[test]
fn counts_history_and_final_pack() {
    let calls = AtomicUsize::new(0);
    let p = FnProblem::new(vec![(-2.0, 3.0); 4], |x: &[f64]| {
        calls.fetch_add(1, Ordering::Relaxed);
        assert!(x.len() == 4 && x.iter().all(|v| (-2.0..=3.0).contains(v)));
        Evaluation::new(Benchmark::Rastrigin.value(x), (x[0] - 1.0).max(0.0))
    });
    let params = GwoParams {
        population: 12,
        iterations: 40,
        seed: 2,
        ..gwo_50x100()
    };
    let res = minimize(&p, &params, &[]).unwrap();
    assert_eq!(res.evaluations, 12 * 41);
    assert_eq!(calls.load(Ordering::Relaxed), res.evaluations);
    assert_eq!(res.history.len(), 41);
    for (i, g) in res.history.iter().enumerate() {
        assert_eq!(g.iteration, i);
        assert!((0.0..=1.0).contains(&g.feasible_share));
    }
    // The best never gets worse under the ranking used (feasibility rules).
    let rank = Constraints::FeasibilityRules;
    for w in res.history.windows(2) {
        let (a, b) = (
            Evaluation::new(w[0].best_objective, w[0].best_violation),
            Evaluation::new(w[1].best_objective, w[1].best_violation),
        );
        assert!(
            rank.compare(&b, &a).is_le(),
            "best got worse: {a:?} → {b:?}"
        );
    }
    let last = res.history.last().unwrap();
    assert_eq!(
        last.best_objective.to_bits(),
        res.best_eval.objective.to_bits()
    );
    // The pack: population-sized, sorted best first, led by `best`, each
    // evaluation matching its point.
    assert_eq!(res.population.len(), 12);
    assert_eq!(res.population[0].0, res.best);
    for w in res.population.windows(2) {
        assert!(rank.compare(&w[0].1, &w[1].1).is_le());
    }
    for (x, e) in &res.population {
        assert_eq!(p.evaluate(x), *e);
    }
}

#[test]
fn warm_start_from_a_near_optimal_wolf_never_returns_worse() {
    for f in Benchmark::ALL {
        let dim = 10;
        let problem = f.problem(dim);
        // Near the optimum (0, or 1 for Rosenbrock), off by 1e−3 per coordinate.
        let centre = if f == Benchmark::Rosenbrock { 1.0 } else { 0.0 };
        let near = vec![centre + 1e-3; dim];
        let f_near = f.value(&near);
        for init in [Init::GoodPointSet, Init::Random] {
            for seed in 0..4 {
                let params = GwoParams {
                    iterations: 10,
                    init,
                    seed,
                    ..gwo_50x100()
                };
                let cold = minimize(&problem, &params, &[]).unwrap();
                let warm = minimize(&problem, &params, std::slice::from_ref(&near)).unwrap();
                assert!(
                    warm.best_eval.objective <= f_near,
                    "{} {init:?} seed {seed}: {} > {f_near}",
                    f.name(),
                    warm.best_eval.objective
                );
                // Ten iterations from cold do not get that close: the warm
                // start is what did it.
                assert!(cold.best_eval.objective > f_near, "{}", f.name());
            }
        }
    }
}

#[test]
fn warm_start_replaces_the_first_wolves_and_is_clamped() {
    // Record the points of the first (initial-pack) evaluation, in wolf
    // order (serial evaluation).
    let seen = Mutex::new(Vec::new());
    let bounds = vec![(-1.0, 1.0), (0.0, 10.0)];
    let p = FnProblem::new(bounds.clone(), |x: &[f64]| {
        seen.lock().unwrap().push(x.to_vec());
        Evaluation::feasible(x[0] * x[0])
    });
    let params = GwoParams {
        population: 6,
        iterations: 1,
        parallel: false,
        ..gwo_50x100()
    };
    let warm = vec![vec![0.25, -3.0], vec![7.0, 4.5]];
    minimize(&p, &params, &warm).unwrap();
    let initial = seen.lock().unwrap()[..6].to_vec();
    assert_eq!(initial[0], vec![0.25, 0.0]);
    assert_eq!(initial[1], vec![1.0, 4.5]);
    let gps = good_point_set(6, &bounds);
    assert_eq!(initial[2..], gps[2..]);
}

#[test]
fn returns_errors_for_bad_inputs() {
    let ok = gwo_50x100();
    let sphere = |b: Vec<(f64, f64)>| FnProblem::new(b, |x: &[f64]| Evaluation::feasible(x[0]));
    let err = |p: &dyn Fn() -> Result<(), OptimError>| p().unwrap_err();
    let run = |b: Vec<(f64, f64)>, params: GwoParams, warm: Vec<Vec<f64>>| {
        minimize(&sphere(b), &params, &warm).map(|_| ())
    };
    assert_eq!(err(&|| run(vec![], ok, vec![])), OptimError::EmptyBounds);
    for (lo, hi) in [
        (1.0, 1.0),
        (2.0, 1.0),
        (f64::NAN, 1.0),
        (0.0, f64::INFINITY),
    ] {
        let e = err(&|| run(vec![(0.0, 1.0), (lo, hi)], ok, vec![]));
        assert!(matches!(e, OptimError::BadBounds { dim: 1, .. }), "{e}");
    }
    let b = || vec![(0.0, 1.0); 2];
    let e = err(&|| {
        run(
            b(),
            GwoParams {
                population: 3,
                ..ok
            },
            vec![],
        )
    });
    assert_eq!(e, OptimError::PopulationTooSmall { population: 3 });
    let e = err(&|| {
        run(
            b(),
            GwoParams {
                iterations: 0,
                ..ok
            },
            vec![],
        )
    });
    assert_eq!(e, OptimError::ZeroIterations);
    for weight in [-1.0, f64::NAN, f64::INFINITY] {
        let params = GwoParams {
            constraints: Constraints::Penalty { weight },
            ..ok
        };
        let e = err(&|| run(b(), params, vec![]));
        assert!(matches!(e, OptimError::BadPenaltyWeight { .. }), "{e}");
    }
    let e = err(&|| run(b(), ok, vec![vec![0.5; 2], vec![0.5; 3]]));
    assert_eq!(
        e,
        OptimError::WarmStartDimension {
            wolf: 1,
            expected: 2,
            got: 3
        }
    );
    let e = err(&|| run(b(), ok, vec![vec![0.5, f64::NAN]]));
    assert!(
        matches!(
            e,
            OptimError::WarmStartNotFinite {
                wolf: 0,
                dim: 1,
                ..
            }
        ),
        "{e}"
    );
    let e = err(&|| {
        run(
            b(),
            GwoParams {
                population: 4,
                ..ok
            },
            vec![vec![0.5; 2]; 5],
        )
    });
    assert_eq!(
        e,
        OptimError::TooManyWarmStarts {
            given: 5,
            population: 4
        }
    );
}

#[test]
fn nan_from_the_problem_names_wolf_and_iteration() {
    // NaN once x[0] > 0.99, which the pack reaches as it climbs to x[0] = 1;
    // which wolf and which iteration must not depend on threading.
    let p = FnProblem::new(vec![(0.0, 1.0); 2], |x: &[f64]| {
        Evaluation::feasible(if x[0] > 0.99 { f64::NAN } else { -x[0] })
    });
    let run = |parallel| {
        minimize(
            &p,
            &GwoParams {
                parallel,
                ..gwo_50x100()
            },
            &[],
        )
        .unwrap_err()
    };
    let e = run(true);
    assert_eq!(e, run(false));
    match &e {
        OptimError::NanObjective { iteration, wolf, x } => {
            assert!(*wolf < 50);
            assert!(x[0] > 0.99);
            let msg = e.to_string();
            assert!(msg.contains(&format!("iteration {iteration}")), "{msg}");
            assert!(msg.contains(&format!("wolf {wolf}")), "{msg}");
        }
        other => panic!("expected NanObjective, got {other}"),
    }
    // A negative or NaN violation is refused in the initial pack.
    for v in [-1.0, f64::NAN] {
        let q = FnProblem::new(vec![(0.0, 1.0); 2], move |_: &[f64]| {
            Evaluation::new(0.0, v)
        });
        let e = minimize(&q, &gwo_50x100(), &[]).unwrap_err();
        assert!(
            matches!(
                e,
                OptimError::BadViolation {
                    iteration: 0,
                    wolf: 0,
                    ..
                }
            ),
            "{e}"
        );
    }
}

/// The pack these tests were tuned on (the old default): 50 wolves, 100
/// iterations, good-point-set start.
fn gwo_50x100() -> GwoParams {
    GwoParams::pack(50, 100, autoshovel_optim::Init::GoodPointSet)
}
