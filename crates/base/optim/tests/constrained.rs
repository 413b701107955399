//! Constrained problems with closed-form optima, solved with Deb's
//! feasibility rules (the default) and with a static penalty.
//!
//! With an active constraint GWO closes in on the boundary slowly (each
//! coordinate moves on its own, and sliding along x + y = 1 needs both):
//! after the default 50 wolves × 100 iterations the worst of 50 seeds is
//! 4.5e−4 above the optimum of the first problem and |x − 0.5| ≤ 1.4e−2
//! (1.3e−4 and 6.9e−3 after 500 iterations); tolerances are set from that.

use approx::assert_abs_diff_eq;
use autoshovel_optim::{minimize, Constraints, Evaluation, FnProblem, GwoParams};

/// min x² + y² s.t. x + y ≥ 1 (g = 1 − x − y ≤ 0). KKT: x = y = 0.5, f = 0.5;
/// the unconstrained minimum (0, 0) is infeasible.
fn disc_above_line() -> FnProblem<impl Fn(&[f64]) -> Evaluation + Sync> {
    FnProblem::new(vec![(-5.0, 5.0); 2], |x: &[f64]| {
        Evaluation::new(x[0] * x[0] + x[1] * x[1], (1.0 - x[0] - x[1]).max(0.0))
    })
}

#[test]
fn feasibility_rules_find_the_kkt_point() {
    for seed in 0..5 {
        let res = minimize(
            &disc_above_line(),
            &GwoParams {
                seed,
                ..gwo_50x100()
            },
            &[],
        )
        .unwrap();
        assert!(
            res.best_eval.is_feasible(),
            "seed {seed}: {:?}",
            res.best_eval
        );
        assert!(res.best_eval.objective >= 0.5 - 1e-12);
        assert_abs_diff_eq!(res.best_eval.objective, 0.5, epsilon = 1e-3);
        assert_abs_diff_eq!(res.best[0], 0.5, epsilon = 2e-2);
        assert_abs_diff_eq!(res.best[1], 0.5, epsilon = 2e-2);
        // Once a feasible wolf is found the best stays feasible.
        let first = res
            .history
            .iter()
            .position(|g| g.best_violation == 0.0)
            .unwrap();
        assert!(res.history[first..].iter().all(|g| g.best_violation == 0.0));
    }
}

#[test]
fn penalty_lands_where_the_penalty_optimum_is() {
    // min x² + y² + w·max(0, 1 − x − y): for w < 1 the minimum is on the
    // infeasible side, x = y = w/2 (stationarity 2x = w), value w²/4 + w(1 − w)
    // — the classic weakness of a small static penalty. For w ≥ 1 it is the
    // true optimum (0.5, 0.5), since the penalty is exact there.
    for (w, x_opt) in [(0.5, 0.25), (10.0, 0.5)] {
        let res = minimize(
            &disc_above_line(),
            &GwoParams {
                constraints: Constraints::Penalty { weight: w },
                seed: 3,
                ..gwo_50x100()
            },
            &[],
        )
        .unwrap();
        assert_abs_diff_eq!(res.best[0], x_opt, epsilon = 1e-2);
        assert_abs_diff_eq!(res.best[1], x_opt, epsilon = 1e-2);
    }
}

#[test]
fn product_under_a_budget_line() {
    // max xy (min −xy) on [0, 4]² s.t. x + 2y ≤ 4: on the line y = (4 − x)/2,
    // −x(4 − x)/2 is least at x = 2, y = 1, f = −2.
    let p = FnProblem::new(vec![(0.0, 4.0); 2], |x: &[f64]| {
        Evaluation::new(-x[0] * x[1], (x[0] + 2.0 * x[1] - 4.0).max(0.0))
    });
    for seed in 0..5 {
        let res = minimize(
            &p,
            &GwoParams {
                seed,
                ..gwo_50x100()
            },
            &[],
        )
        .unwrap();
        assert!(res.best_eval.is_feasible());
        assert!(res.best_eval.objective >= -2.0 - 1e-12);
        assert_abs_diff_eq!(res.best_eval.objective, -2.0, epsilon = 5e-3);
    }
}

/// The pack these tests were tuned on (the old default): 50 wolves, 100
/// iterations, good-point-set start.
fn gwo_50x100() -> GwoParams {
    GwoParams::pack(50, 100, autoshovel_optim::Init::GoodPointSet)
}
