//! Criterion benchmarks of the dig planner: one objective evaluation ([RS eqs. 22–35]
//! on 121 samples) and one whole plan (50 wolves × 100 iterations).

use autoshovel_dig::{plan_dig, Decision, DigModel, DigSurface, MachineProfile};
use autoshovel_optim::GwoParams;
use autoshovel_surface::PileShape;
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn model() -> DigModel {
    let p = MachineProfile::scale_model();
    DigModel::new(
        &p,
        DigSurface::from_shape(PileShape::Typical, p.dipper.width_m),
    )
    .unwrap()
}

fn evaluation(c: &mut Criterion) {
    let m = model();
    let d = Decision::from_bends(0.05, -0.03, 9.0, 0.22, 0.28);
    c.bench_function("dig/evaluate (121 samples)", |b| {
        b.iter(|| m.evaluate(black_box(&d)))
    });
}

fn whole_plan(c: &mut Criterion) {
    let m = model();
    let mut g = c.benchmark_group("dig/plan typical 5050 evaluations");
    g.sample_size(20);
    for parallel in [false, true] {
        let gwo_only: autoshovel_dig::DigSearch = GwoParams {
            seed: 1,
            parallel,
            ..autoshovel_dig::gwo_preset()
        }
        .into();
        let preset = autoshovel_dig::search_preset();
        let polished = autoshovel_dig::DigSearch {
            gwo: GwoParams {
                seed: 1,
                parallel,
                ..preset.gwo
            },
            ..preset
        };
        let threads = if parallel { "parallel" } else { "serial" };
        g.bench_function(format!("gwo 50x100 {threads}"), |b| {
            b.iter(|| plan_dig(&m, &gwo_only, &[]).unwrap())
        });
        g.bench_function(format!("gwo 150x25 + cma 1150 {threads}"), |b| {
            b.iter(|| plan_dig(&m, &polished, &[]).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, evaluation, whole_plan);
criterion_main!(benches);
