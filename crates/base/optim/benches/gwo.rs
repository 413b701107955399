//! Criterion benchmarks of the Grey Wolf Optimizer (Mirjalili et al. 2014;
//! rope-shovel paper [RS eq. 37]): one full run of each benchmark function in
//! the paper's setting (30-D, 30 wolves × 500 iterations, random start),
//! serial and parallel, and a 5-D sphere run with 50 wolves × 100
//! iterations (the dig planner's size), where the function costs almost
//! nothing, to show the optimiser's own overhead per run.
//!
//! Run: `cargo bench -p autoshovel-optim --bench gwo`

use std::hint::black_box;

use autoshovel_optim::benchmarks::Benchmark;
use autoshovel_optim::{minimize, GwoParams, Init};
use criterion::{criterion_group, criterion_main, Criterion};

fn bench_gwo(c: &mut Criterion) {
    let mut group = c.benchmark_group("gwo_30d_30x500");
    group.sample_size(20);
    for f in Benchmark::ALL {
        let problem = f.problem(30);
        for parallel in [false, true] {
            let params = GwoParams {
                parallel,
                seed: 1,
                ..GwoParams::mirjalili_2014()
            };
            let label = format!(
                "{}/{}",
                f.name(),
                if parallel { "parallel" } else { "serial" }
            );
            group.bench_function(label, |b| {
                b.iter(|| minimize(black_box(&problem), &params, &[]).unwrap())
            });
        }
    }
    group.finish();

    let mut group = c.benchmark_group("gwo_5d_50x100");
    let problem = Benchmark::Sphere.problem(5);
    for (label, init, parallel) in [
        ("sphere/good-point-set/serial", Init::GoodPointSet, false),
        ("sphere/random/serial", Init::Random, false),
        ("sphere/good-point-set/parallel", Init::GoodPointSet, true),
    ] {
        let params = GwoParams {
            init,
            parallel,
            seed: 1,
            population: 50,
            iterations: 100,
            ..GwoParams::default()
        };
        group.bench_function(label, |b| {
            b.iter(|| minimize(black_box(&problem), &params, &[]).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, bench_gwo);
criterion_main!(benches);
