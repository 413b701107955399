//! Criterion benchmarks of the dig planner: one objective evaluation ([RS eqs. 22–35]
//! on 121 samples) and one whole plan: the paper's GWO (50 wolves × 100
//! iterations) and the default search (that, then a CMA-ES polish of 20 000).

use autoshovel_optim::GwoParams;
use autoshovel_rope_shovel_dig::{plan_dig, Decision, DigModel, MachineProfile};
use autoshovel_terrain::PileShape;
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn model() -> DigModel {
    let p = MachineProfile::scale_model();
    // The typical pile rebuilt from Tables 4–5, as plan-dig plans it.
    let pile = autoshovel_rope_shovel_dig::paper_pile(&p, PileShape::Typical).unwrap();
    DigModel::new(&p, pile.surface(p.dipper.width_m)).unwrap()
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
    let mut g = c.benchmark_group("dig/plan typical");
    g.sample_size(20);
    for parallel in [false, true] {
        let gwo_only: autoshovel_rope_shovel_dig::DigSearch = GwoParams {
            seed: 1,
            parallel,
            ..autoshovel_rope_shovel_dig::gwo_preset()
        }
        .into();
        let preset = autoshovel_rope_shovel_dig::search_preset();
        let polished = autoshovel_rope_shovel_dig::DigSearch {
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
        g.bench_function(format!("gwo 50x100 + cma 20000 {threads}"), |b| {
            b.iter(|| plan_dig(&m, &polished, &[]).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, evaluation, whole_plan);
criterion_main!(benches);
