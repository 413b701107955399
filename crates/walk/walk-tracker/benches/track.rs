//! One control step of each tracker (aim for the fuzzy one: under 5 µs) and a
//! whole Fig. 9a simulation (aim: at least 10,000× faster than real time).

use autoshovel_core::{Pose2, Vec2};
use autoshovel_walk_planner::Direction;
use autoshovel_walk_tracker::scenario::resolve;
use autoshovel_walk_tracker::*;
use criterion::{black_box, criterion_group, criterion_main, Criterion};

fn steps(c: &mut Criterion) {
    let leg = RefLeg::new(
        Direction::Forward,
        vec![Vec2::new(0.0, 0.0), Vec2::new(30.0, 30.0)],
        None,
    )
    .unwrap();
    let crawler = CrawlerParams::default();
    let pose = Pose2::new(5.0, 4.6, 0.7);
    let dev = deviations(&leg, pose, 1.0, None);
    let input = ControlInput {
        leg: &leg,
        pose,
        dev: &dev,
        speed_mps: 1.0,
        dt_s: 0.1,
        crawler: &crawler,
    };
    let mut g = c.benchmark_group("control_step");
    let mut fuzzy = FuzzyTracker::new(FuzzyParams::default());
    g.bench_function("fuzzy", |b| b.iter(|| fuzzy.step(black_box(&input))));
    let mut pid = Pid::new(PidParams::default());
    g.bench_function("pid", |b| b.iter(|| pid.step(black_box(&input))));
    let mut pp = PurePursuit {
        params: PurePursuitParams::default(),
    };
    g.bench_function("pure-pursuit", |b| b.iter(|| pp.step(black_box(&input))));
    g.bench_function("deviations (eqs. 21-22)", |b| {
        b.iter(|| deviations(&leg, black_box(pose), 1.0, Some(6.0)))
    });
    g.finish();
}

fn whole_runs(c: &mut Criterion) {
    let mut g = c.benchmark_group("simulate");
    g.sample_size(20);
    for name in ["fig9a", "curve"] {
        let s = resolve(name, None, 1).unwrap();
        g.bench_function(format!("{name} fuzzy"), |b| {
            b.iter(|| {
                simulate(
                    black_box(&s.setup),
                    &mut FuzzyTracker::new(FuzzyParams::default()),
                )
            })
        });
    }
    g.finish();
}

criterion_group!(benches, steps, whole_runs);
criterion_main!(benches);
