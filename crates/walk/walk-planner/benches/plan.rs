//! Plan time of the built-in scenarios (issue: under 5 ms each on 2 cores),
//! one field evaluation, and the Theta* reference.

use autoshovel_core::Vec2;
use autoshovel_walk_planner::apf::{field_force, Target};
use autoshovel_walk_planner::{astar, plan_path, AstarParams, FieldKind, PlanOptions, Scenario};
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn plans(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan_path");
    for name in ["straight", "curve", "v-shape"] {
        let s = Scenario::builtin(name).expect("built-in");
        let opts = PlanOptions::new(FieldKind::Improved);
        g.bench_function(format!("improved-apf/{name}"), |b| {
            b.iter(|| plan_path(black_box(&s), &opts).expect("plans"))
        });
    }
    let s = Scenario::builtin("v-shape").expect("built-in");
    let opts = PlanOptions::new(FieldKind::Classic);
    g.bench_function("apf/v-shape", |b| {
        b.iter(|| plan_path(black_box(&s), &opts).expect("plans"))
    });
    g.finish();
}

fn field(c: &mut Criterion) {
    let s = Scenario::builtin("curve").expect("built-in");
    let t = Target {
        position: s.goal.position(),
        motion_heading_rad: s.goal.theta,
    };
    let p = PlanOptions::new(FieldKind::Improved).apf;
    c.bench_function("field_force/curve", |b| {
        b.iter(|| {
            field_force(
                &s.map,
                black_box(Vec2::new(12.0, 2.0)),
                &t,
                1.0,
                FieldKind::Improved,
                &p,
            )
        })
    });
}

fn reference(c: &mut Criterion) {
    let s = Scenario::builtin("curve").expect("built-in");
    c.bench_function("theta_star/curve", |b| {
        b.iter(|| {
            astar(
                &s.map,
                s.start.position(),
                s.goal.position(),
                1.0,
                &AstarParams::default(),
            )
            .expect("route")
        })
    });
}

criterion_group!(benches, plans, field, reference);
criterion_main!(benches);
