//! Criterion benchmarks of the two-level planner: a whole plan with one
//! contact, detour and re-plan (both paper cases), the level-1 plan alone,
//! and one forward search.

use autoshovel_core::Vec2;
use autoshovel_excavate::ground::Ground;
use autoshovel_excavate::level1::{plan_level1, Level1Request, StepSearch};
use autoshovel_excavate::obstacle::Envelope;
use autoshovel_excavate::search::{forward_search, SearchParams};
use autoshovel_excavate::{excavate, AvoidSide, Backhoe, MachineProfile, Scenario};
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
    let ground = Ground::flat();
    let search = StepSearch {
        machine: &m,
        ground: &ground,
        bucket_width_m: 1.0,
        step_m: 0.05,
        trapezoids: 100,
        speed_fraction: 0.5,
        min_segment_time_s: 1.0,
        known: &[],
        refine: false,
        max_overdig_m: 0.15,
    };
    let req = Level1Request {
        start_x_m: 7.0,
        depth_m: 0.7,
        target_volume_m3: 0.9,
        attitude_rad: [
            -80f64.to_radians(),
            -140f64.to_radians(),
            -200f64.to_radians(),
        ],
    };
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
