//! Criterion benchmarks of the two-level planner: a whole plan with one
//! contact, detour and re-plan (both paper cases), the level-1 plan alone,
//! and one forward search.

use autoshovel_core::Vec2;
use autoshovel_excavator_dig::level1::plan_level1;
use autoshovel_excavator_dig::obstacle::Envelope;
use autoshovel_excavator_dig::search::{forward_search, SearchParams};
use autoshovel_excavator_dig::{excavate, AvoidSide, Backhoe, MachineProfile, Scenario};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn whole_plan(c: &mut Criterion) {
    let profile = MachineProfile::default();
    let mut g = c.benchmark_group("excavate");
    for s in [Scenario::paper_over(), Scenario::paper_under()] {
        g.bench_function(format!("{} (one contact, detour, re-plan)", s.name), |b| {
            b.iter(|| excavate(black_box(&s), &profile).unwrap())
        });
    }
    let two = Scenario::builtin("two-boulders").unwrap();
    g.bench_function("two-boulders (two contacts, refined volume)", |b| {
        b.iter(|| excavate(black_box(&two), &profile).unwrap())
    });
    g.finish();
}

fn pieces(c: &mut Criterion) {
    let m = Backhoe::new(&MachineProfile::default());
    let paper = Scenario::paper_over();
    let search = paper.step_search(&m, 1.0, &[]);
    let req = paper.level1_request();
    c.bench_function("level1/paper (two step searches)", |b| {
        b.iter(|| plan_level1(black_box(&search), &req).unwrap())
    });
    let boulder = Envelope::new(Vec2::new(6.64, -0.60), 0.25);
    let contact = Vec2::new(6.6812, -0.3534);
    let normal = (contact - boulder.center()).normalize();
    let params = SearchParams {
        step_m: 0.05,
        clearance_m: 0.1,
        window_m: 1.0,
    };
    c.bench_function("forward_search/paper-over", |b| {
        b.iter(|| {
            forward_search(
                &m,
                -1.73,
                contact,
                normal,
                &boulder,
                AvoidSide::Over,
                &[boulder],
                6.24,
                black_box(&params),
            )
            .unwrap()
        })
    });
}

criterion_group!(benches, whole_plan, pieces);
criterion_main!(benches);
