//! Quality against the published GWO results of Mirjalili, Mirjalili &
//! Lewis 2014 (Tables 5–6; 30 dimensions, 30 wolves, 500 iterations, random
//! start, mean best objective over 30 runs):
//!
//! | function | published mean | asserted mean over our 10 seeds |
//! |---|---|---|
//! | F1 sphere | 6.59e−28 | ≤ 6.59e−28 |
//! | F5 Rosenbrock | 26.81 (std 69.9) | < 28.8 |
//! | F9 Rastrigin | 0.31 | ≤ 0.31 |
//! | F10 Ackley | 1.06e−13 | ≤ 1.06e−13 |
//!
//! The Rosenbrock bound is the published mean plus 2 (7 %), far inside the
//! published spread, and below f(0) = 29, where a stalled run sits: our
//! 30-seed mean is 27.3, a little above the paper's 26.8. The other three
//! are the published means themselves. Ten seeds keep this test near a
//! second at the test profile's opt-level 1; the example
//! `benchmark_table -- --runs 30` gives the 30-run table.

use autoshovel_optim::benchmarks::Benchmark;
use autoshovel_optim::{minimize, GwoParams, Init};

const SEEDS: u64 = 10;

fn mean_best(f: Benchmark, init: Init) -> f64 {
    let problem = f.problem(30);
    let sum: f64 = (0..SEEDS)
        .map(|seed| {
            let params = GwoParams {
                init,
                seed,
                ..GwoParams::mirjalili_2014()
            };
            minimize(&problem, &params, &[])
                .expect("benchmark run")
                .best_eval
                .objective
        })
        .sum();
    sum / SEEDS as f64
}

fn check(f: Benchmark, limit: f64) {
    for init in [Init::Random, Init::GoodPointSet] {
        let mean = mean_best(f, init);
        println!("{} {init:?}: mean {mean:.3e} (limit {limit:.3e})", f.name());
        assert!(
            mean <= limit,
            "{} with {init:?}: mean best {mean:.3e} over {SEEDS} seeds is worse than {limit:.3e} \
             (published {:.3e})",
            f.name(),
            f.published_gwo().mean
        );
    }
}

#[test]
fn f1_sphere_reaches_published_mean() {
    check(Benchmark::Sphere, Benchmark::Sphere.published_gwo().mean);
}

#[test]
fn f5_rosenbrock_reaches_published_quality() {
    check(
        Benchmark::Rosenbrock,
        Benchmark::Rosenbrock.published_gwo().mean + 2.0,
    );
}

#[test]
fn f9_rastrigin_reaches_published_mean() {
    check(
        Benchmark::Rastrigin,
        Benchmark::Rastrigin.published_gwo().mean,
    );
}

#[test]
fn f10_ackley_reaches_published_mean() {
    check(Benchmark::Ackley, Benchmark::Ackley.published_gwo().mean);
}
