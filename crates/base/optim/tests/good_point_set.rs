//! The good point set (rope-shovel paper §4.5; Hua & Wang 1981): it is
//! deterministic, covers the box more evenly than uniform random points
//! where it should, and what it buys the optimiser — measured, not assumed.
//!
//! Evenness is measured by two closed-form discrepancies of points in
//! [0, 1)^D: the L2-star discrepancy (Warnock 1972) and the centred L2
//! discrepancy (Hickernell 1998), each compared with 100 seeded uniform
//! random sets of the same size. Findings (also in the crate's docs):
//!
//! | N × D | L2*: good point set better than | CD2: better than |
//! |---|---|---|
//! | 50 × 3 | 100 / 100 random sets | 100 / 100 |
//! | 200 × 5 | 99 / 100 | 100 / 100 |
//! | 30 × 30 (Mirjalili's setting) | 100 / 100 | 41 / 100 |
//! | 50 × 5 (the dig planner's size) | 28 / 100 | 1 / 100 |
//!
//! So at the dig planner's 50 wolves in 5 dimensions the set is *less*
//! even than random points: its advantage is asymptotic in N (Hua & Wang's
//! bound holds up to a constant that grows with D) and has not set in at
//! N = 50.

use autoshovel_optim::benchmarks::Benchmark;
use autoshovel_optim::{good_point_set, minimize, unit_good_point_set, GwoParams, Init};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// L2-star discrepancy (Warnock's formula).
fn l2_star(p: &[Vec<f64>]) -> f64 {
    let n = p.len() as f64;
    let d = p[0].len() as i32;
    let single: f64 = p
        .iter()
        .map(|x| x.iter().map(|v| 0.5 * (1.0 - v * v)).product::<f64>())
        .sum();
    let mut pairs = 0.0;
    for x in p {
        for y in p {
            pairs += x
                .iter()
                .zip(y)
                .map(|(u, v)| 1.0 - u.max(*v))
                .product::<f64>();
        }
    }
    (3f64.powi(-d) - 2.0 * single / n + pairs / (n * n)).sqrt()
}

/// Centred L2 discrepancy (Hickernell 1998).
fn centred_l2(p: &[Vec<f64>]) -> f64 {
    let n = p.len() as f64;
    let d = p[0].len() as i32;
    let single: f64 = p
        .iter()
        .map(|x| {
            x.iter()
                .map(|v| 1.0 + 0.5 * (v - 0.5).abs() - 0.5 * (v - 0.5).powi(2))
                .product::<f64>()
        })
        .sum();
    let mut pairs = 0.0;
    for x in p {
        for y in p {
            pairs += x
                .iter()
                .zip(y)
                .map(|(u, v)| {
                    1.0 + 0.5 * (u - 0.5).abs() + 0.5 * (v - 0.5).abs() - 0.5 * (u - v).abs()
                })
                .product::<f64>();
        }
    }
    ((13.0f64 / 12.0).powi(d) - 2.0 * single / n + pairs / (n * n)).sqrt()
}

/// How many of 100 seeded random sets the good point set beats.
fn beats(n: usize, d: usize, disc: fn(&[Vec<f64>]) -> f64) -> usize {
    let g = disc(&unit_good_point_set(n, d));
    (0..100u64)
        .filter(|&seed| {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let r: Vec<Vec<f64>> = (0..n)
                .map(|_| (0..d).map(|_| rng.gen()).collect())
                .collect();
            g < disc(&r)
        })
        .count()
}

#[test]
fn deterministic_and_inside_the_box() {
    let bounds = [(-100.0, 100.0), (0.0, 1e-3), (-5.12, 5.12)];
    let a = good_point_set(200, &bounds);
    assert_eq!(a, good_point_set(200, &bounds));
    // A prefix of a longer set is the shorter set (point i does not depend on N).
    assert_eq!(a[..50], good_point_set(50, &bounds)[..]);
    for x in &a {
        for (v, (lo, hi)) in x.iter().zip(bounds) {
            assert!((lo..hi).contains(v), "{v} outside [{lo}, {hi})");
        }
    }
    // And all points are distinct.
    for i in 0..a.len() {
        for j in 0..i {
            assert_ne!(a[i], a[j]);
        }
    }
}

#[test]
fn more_even_than_random_where_it_should_be() {
    assert_eq!(beats(50, 3, l2_star), 100);
    assert_eq!(beats(50, 3, centred_l2), 100);
    assert!(beats(200, 5, l2_star) >= 95);
    assert!(beats(200, 5, centred_l2) >= 95);
    assert!(beats(30, 30, l2_star) >= 95);
}

#[test]
fn less_even_than_random_at_the_dig_planners_size() {
    // A documented weakness, kept as a test so it is not forgotten: 50
    // points in 5-D are less even than most random sets.
    assert!(beats(50, 5, centred_l2) <= 5);
    assert!(beats(50, 5, l2_star) <= 50);
}

/// Mean over 30 seeds of (initial best, final best) for one start.
fn means(f: Benchmark, dim: usize, iterations: usize, init: Init) -> (f64, f64) {
    let p = f.problem(dim);
    let runs = 30;
    let (mut first, mut last) = (0.0, 0.0);
    for seed in 0..runs {
        let params = GwoParams {
            iterations,
            init,
            seed,
            ..gwo_50x100()
        };
        let r = minimize(&p, &params, &[]).unwrap();
        first += r.history[0].best_objective / runs as f64;
        last += r.best_eval.objective / runs as f64;
    }
    (first, last)
}

#[test]
fn what_the_good_point_set_buys_the_optimiser() {
    // 50 wolves in 5-D. The good point set's initial best beats the mean of
    // random starts on sphere (1.6e3 vs 3.7e3), Rosenbrock (6.3e5 vs 2.4e6)
    // and Ackley (15.7 vs 17.8), not on Rastrigin (46.4 vs 45.3).
    for f in [Benchmark::Sphere, Benchmark::Rosenbrock, Benchmark::Ackley] {
        let (gps, _) = means(f, 5, 1, Init::GoodPointSet);
        let (rnd, _) = means(f, 5, 1, Init::Random);
        assert!(
            gps < rnd,
            "{}: initial best {gps:.3e} vs random {rnd:.3e}",
            f.name()
        );
    }
    // With a short budget (20 iterations) the head start still shows on
    // Rosenbrock: mean best 6.0 against 11.2 (over 200 seeds: 5.0 vs 13.1,
    // the good point set better or equal in 60 % of the runs).
    let (_, gps) = means(Benchmark::Rosenbrock, 5, 20, Init::GoodPointSet);
    let (_, rnd) = means(Benchmark::Rosenbrock, 5, 20, Init::Random);
    assert!(
        gps <= rnd,
        "Rosenbrock, 20 iterations: {gps:.3} vs random {rnd:.3}"
    );
    // With the full 100 iterations the two starts are indistinguishable on
    // all four functions (e.g. Rosenbrock 1.89 vs 1.82, sphere 7.7e−24 vs
    // 1.4e−24); nothing is asserted there.
}

/// The pack these tests were tuned on (the old default): 50 wolves, 100
/// iterations, good-point-set start.
fn gwo_50x100() -> GwoParams {
    GwoParams::pack(50, 100, autoshovel_optim::Init::GoodPointSet)
}
